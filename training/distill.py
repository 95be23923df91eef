"""The paper's pseudo-ground-truth builder: a 10x ensemble of a teacher's predictions.

For each photo the teacher runs at five square resolutions (default 512, 768, 1024, 1600,
1920, as in the paper; or with keep_aspect at those long sides, the photo's aspect kept)
on the image and on its horizontal mirror (the mirrored prediction is flipped back). Each
of the ten predictions is normalised on its own, resized bilinearly to the largest size,
and the ten are combined by the per-pixel median. The result is finally resized to the
photo's own size.

Normalisation: median and mean absolute deviation, d' = (d - median(d)) / MAD(d), the
scale-and-shift alignment MiDaS uses for its own targets. It makes predictions at
different resolutions comparable (a teacher's disparity scale drifts with input size) and,
unlike min-max, is not thrown off by a few extreme pixels. The ensemble is then min-max
mapped to [0, 1] so the stored maps share one range; training normalises again anyway.

The teacher is any callable `teacher(rgb) -> disparity` taking a float32 H x W x 3 array
in [0, 1] and returning an H' x W' disparity (larger = nearer) of any size; it is resized
to the square it was given. See training/README.md for plugging in MiDaS.

    /usr/bin/python3 training/distill.py --photos DIR --out DIR --teacher-checkpoint RUN/checkpoint.pt

writes OUT/NAME.jpg (the photo, a symlink) and OUT/NAME.npy (float32 disparity in [0, 1]),
the `pairs:OUT` data source of train_depth.py, and OUT/labels.tsv as `ampi distill` writes
it, so OUT also serves train_depth.py --teacher-labels (gpu_run.py makes its teacher's
labels this way on the GPU machine, where the engine is not built).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import torch
import torch.nn.functional as F

sys.path.insert(0, str(Path(__file__).resolve().parent))   # depth_model, export_depth, ampw
import photo_folder  # noqa: E402  (the photo listing)

PAPER_RESOLUTIONS = (512, 768, 1024, 1600, 1920)

Teacher = Callable[[np.ndarray], np.ndarray]


def resize_bilinear(image: np.ndarray, height: int, width: int) -> np.ndarray:
    """H x W or H x W x C float array, bilinear with half-pixel centres (align_corners=False)."""
    t = torch.from_numpy(np.ascontiguousarray(image, dtype=np.float32))
    t = t[None, None] if t.dim() == 2 else t.permute(2, 0, 1)[None]
    r = F.interpolate(t, size=(height, width), mode="bilinear", align_corners=False)[0]
    return (r[0] if image.ndim == 2 else r.permute(1, 2, 0)).numpy()


def normalise_median_mad(disparity: np.ndarray, eps: float = 1e-8) -> np.ndarray:
    d = disparity.astype(np.float64)
    median = np.median(d)
    mad = np.mean(np.abs(d - median))
    return ((d - median) / max(mad, eps)).astype(np.float32)


def ensemble_sizes(height: int, width: int, resolutions: Sequence[int], keep_aspect: bool = False):
    """The (h, w) the teacher sees for each resolution: the paper's squares, or with
    keep_aspect the photo brought to that long side, its aspect kept (networks trained
    on whole photos of one aspect, as ours are, do worse on squeezed squares)."""
    if not keep_aspect:
        return [(side, side) for side in resolutions]
    long_side = max(height, width)
    return [(max(1, round(height * side / long_side)), max(1, round(width * side / long_side)))
            for side in resolutions]


def ensemble_predictions(rgb: np.ndarray, teacher: Teacher,
                         resolutions: Sequence[int] = PAPER_RESOLUTIONS, keep_aspect: bool = False) -> np.ndarray:
    """The normalised predictions, two per resolution, each at the largest size: [2R, H, W]."""
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"expected an H x W x 3 image, got shape {rgb.shape}")
    sizes = ensemble_sizes(rgb.shape[0], rgb.shape[1], resolutions, keep_aspect)
    largest = max(sizes, key=lambda size: size[0] * size[1])
    predictions = []
    for height, width in sizes:
        scaled = resize_bilinear(rgb, height, width)
        for flipped in (False, True):
            x = scaled[:, ::-1] if flipped else scaled
            d = np.asarray(teacher(np.ascontiguousarray(x)), dtype=np.float32)
            if d.ndim != 2:
                raise ValueError(f"the teacher returned shape {d.shape}, expected a 2-D disparity")
            if d.shape != (height, width):
                d = resize_bilinear(d, height, width)
            if flipped:
                d = d[:, ::-1]
            predictions.append(resize_bilinear(normalise_median_mad(d), *largest))
    return np.stack(predictions)


def pseudo_ground_truth(rgb: np.ndarray, teacher: Teacher,
                        resolutions: Sequence[int] = PAPER_RESOLUTIONS, keep_aspect: bool = False) -> np.ndarray:
    """The per-pixel median of the ensemble, at the photo's own size, mapped to [0, 1]."""
    median = np.median(ensemble_predictions(rgb, teacher, resolutions, keep_aspect), axis=0)
    d = resize_bilinear(median, rgb.shape[0], rgb.shape[1])
    lo, hi = float(d.min()), float(d.max())
    return ((d - lo) / max(hi - lo, 1e-8)).astype(np.float32)


def network_teacher(weights: str, model_name: str = "heavy", device: str = "cpu") -> Teacher:
    """Our own trained network as a teacher (self-distillation): a train_depth.py
    checkpoint of `model_name`, or an exported .ampw (whose architecture it names). An
    input whose sides are not multiples of the network's is edge-replicated up to them and
    the output cropped back, as the engine runs it (the paper's squares are multiples of
    32 already)."""
    import depth_model
    if weights.endswith(".ampw"):
        import export_depth
        model = export_depth.import_ampw(weights)
    else:
        model = depth_model.build(model_name)
        model.load_state_dict(torch.load(weights, map_location="cpu")["model"])
    model = model.to(device).eval()

    @torch.no_grad()
    def teacher(rgb: np.ndarray) -> np.ndarray:
        h, w = rgb.shape[:2]
        x = torch.from_numpy(np.ascontiguousarray(rgb)).permute(2, 0, 1)[None].to(device)
        x = F.pad(x, (0, (-w) % model.multiple, 0, (-h) % model.multiple), mode="replicate")
        return model.predict(x.contiguous(memory_format=torch.channels_last))[0, 0, :h, :w].cpu().numpy()

    return teacher


def read_label_folder(folder) -> tuple[Path, dict]:
    """An `ampi distill` label folder: (its photo folder, {photo path relative to that
    folder: label file}), from the folder's labels.tsv (distill/label_folder.h)."""
    lines = (Path(folder) / "labels.tsv").read_text().splitlines()
    if not lines or lines[0] != "ampi-distill\t1":
        raise ValueError(f"{folder}/labels.tsv: not a label folder of ampi distill")
    header = dict(line.split("\t", 1) for line in lines[1:4])
    labels = {}
    for line in lines[4:]:
        label, photo = line.split("\t")
        labels[photo] = Path(folder) / label
    return Path(header["images"]), labels


def read_disparity(path: Path) -> np.ndarray:
    """A float32 H x W disparity from NAME.npy or a 16-bit PNG (scaled to [0, 1])."""
    if path.suffix == ".npy":
        return np.load(path).astype(np.float32)
    from PIL import Image
    with Image.open(path) as image:
        return np.asarray(image, dtype=np.float32) / 65535.0


def teacher_line(weights: str, model_name: str) -> str:
    """labels.tsv's teacher line, as `ampi distill` writes it: file name, architecture,
    variant (a checkpoint's architecture is train_depth.py's)."""
    if weights.endswith(".ampw"):
        from ampw import read_ampw
        meta, _ = read_ampw(weights)
        return f"teacher\t{Path(weights).name}\t{meta['arch']}\t{meta['depth.variant']}"
    return f"teacher\t{Path(weights).name}\ttrain_depth.py checkpoint\t{model_name}"


def open_manifest(out: Path, header: list[str]) -> set:
    """OUT/labels.tsv with `header`, created or reopened; the photos it already lists.
    As `ampi distill` (distill/label_folder.h): a folder made with another teacher,
    other resolutions or another photo folder is refused, and so is a non-empty folder
    without labels.tsv."""
    manifest = out / "labels.tsv"
    if not manifest.exists():
        if out.exists() and any(out.iterdir()):
            raise SystemExit(f"{out}: not empty and has no labels.tsv; give a new folder")
        out.mkdir(parents=True, exist_ok=True)
        manifest.write_text("\n".join(header) + "\n")
        return set()
    lines = manifest.read_text().splitlines()
    if lines[:len(header)] != header:
        raise SystemExit(f"{manifest}: made with another teacher, resolutions or photo folder "
                         f"({' | '.join(lines[1:len(header)])})")
    return {line.split("\t")[1] for line in lines[len(header):]}


def label_folder(photos: Path, out: Path, teacher: Teacher, resolutions: Sequence[int], keep_aspect: bool = False,
                 teacher_name: str = "teacher\tunnamed\t-\t-"):
    """Labels every photo under `photos` into OUT: NAME.npy (float32 disparity in [0, 1]
    at the photo's size), a link NAME.jpg|png to the photo (the `pairs:OUT` source), and
    a line in OUT/labels.tsv, `ampi distill`'s format, so that OUT is also a folder for
    train_depth.py --teacher-labels and --data distilled:OUT. Resumable: a photo is
    listed once its label is written, and listed photos are skipped."""
    from PIL import Image, ImageOps  # Debian's python3-pil
    header = ["ampi-distill\t1", teacher_name,
              f"resolutions\t{','.join(map(str, resolutions))}" + ("\taspect kept" if keep_aspect else ""),
              f"images\t{photos.resolve()}"]
    done = open_manifest(out, header)
    names = photo_folder.image_files(photos)
    for i, path in enumerate(names):
        rel = path.relative_to(photos).as_posix()
        if rel in done:
            continue
        started = time.monotonic()
        stem = "_".join(path.relative_to(photos).with_suffix("").parts)
        image = ImageOps.exif_transpose(Image.open(path)).convert("RGB")
        full_size = image.size
        # area-averaged down to the largest side first, as `ampi distill` does: the
        # bilinear resizes would alias a large photo
        scale = max(resolutions) / max(full_size)
        if scale < 1:
            image = image.resize((max(1, round(image.width * scale)), max(1, round(image.height * scale))), Image.BOX)
        label = pseudo_ground_truth(np.asarray(image, dtype=np.float32) / 255.0, teacher, resolutions, keep_aspect)
        np.save(out / f"{stem}.npy", resize_bilinear(label, full_size[1], full_size[0]))
        link = out / f"{stem}{path.suffix.lower()}"
        if not link.exists():
            link.symlink_to(path.resolve())
        with open(out / "labels.tsv", "a") as manifest:
            manifest.write(f"{stem}.npy\t{rel}\n")
        # the time each photo took: on a GPU machine this step took a third of a call
        print(f"[{i + 1}/{len(names)}] {path} -> {out / stem}.npy {time.monotonic() - started:.2f} s", flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--photos", required=True, help="folder of photos (searched recursively)")
    p.add_argument("--out", required=True, help="output folder: NAME.npy pseudo-labels + photo links")
    p.add_argument("--teacher-checkpoint", required=True,
                   help="the teacher: a train_depth.py checkpoint.pt (of --teacher-model) or an exported .ampw")
    p.add_argument("--teacher-model", default="heavy", help="the checkpoint's architecture (an .ampw names its own)")
    p.add_argument("--resolutions", default=",".join(map(str, PAPER_RESOLUTIONS)),
                   help="comma-separated square sides")
    p.add_argument("--keep-aspect", action="store_true",
                   help="the resolutions are long sides, the photo's aspect kept (as ampi distill --keep-aspect)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--device", default="cpu", help="where the teacher runs (cuda on a GPU machine)")
    args = p.parse_args(argv)
    torch.set_num_threads(args.threads)
    resolutions = [int(v) for v in args.resolutions.split(",")]
    label_folder(Path(args.photos), Path(args.out),
                 network_teacher(args.teacher_checkpoint, args.teacher_model, args.device), resolutions,
                 args.keep_aspect, teacher_line(args.teacher_checkpoint, args.teacher_model))


if __name__ == "__main__":
    main()

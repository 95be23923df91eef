"""The paper's pseudo-ground-truth builder: a 10x ensemble of a teacher's predictions.

For each photo the teacher runs at five square resolutions (default 512, 768, 1024, 1600,
1920, as in the paper) on the image and on its horizontal mirror (the mirrored prediction
is flipped back). Each of the ten predictions is normalised on its own, resized bilinearly
to the largest resolution, and the ten are combined by the per-pixel median. The result
is finally resized to the photo's own size.

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
the `pairs:OUT` data source of train_depth.py.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import torch
import torch.nn.functional as F

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


def ensemble_predictions(rgb: np.ndarray, teacher: Teacher,
                         resolutions: Sequence[int] = PAPER_RESOLUTIONS) -> np.ndarray:
    """The ten normalised predictions, each at the largest square resolution: [10, S, S]."""
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"expected an H x W x 3 image, got shape {rgb.shape}")
    largest = max(resolutions)
    predictions = []
    for side in resolutions:
        square = resize_bilinear(rgb, side, side)
        for flipped in (False, True):
            x = square[:, ::-1] if flipped else square
            d = np.asarray(teacher(np.ascontiguousarray(x)), dtype=np.float32)
            if d.ndim != 2:
                raise ValueError(f"the teacher returned shape {d.shape}, expected a 2-D disparity")
            if d.shape != (side, side):
                d = resize_bilinear(d, side, side)
            if flipped:
                d = d[:, ::-1]
            predictions.append(resize_bilinear(normalise_median_mad(d), largest, largest))
    return np.stack(predictions)


def pseudo_ground_truth(rgb: np.ndarray, teacher: Teacher,
                        resolutions: Sequence[int] = PAPER_RESOLUTIONS) -> np.ndarray:
    """The per-pixel median of the ensemble, at the photo's own size, mapped to [0, 1]."""
    median = np.median(ensemble_predictions(rgb, teacher, resolutions), axis=0)
    d = resize_bilinear(median, rgb.shape[0], rgb.shape[1])
    lo, hi = float(d.min()), float(d.max())
    return ((d - lo) / max(hi - lo, 1e-8)).astype(np.float32)


def network_teacher(checkpoint: str, model_name: str = "heavy", multiple: int = 32) -> Teacher:
    """Our own trained network as a teacher (self-distillation: heavy labels photos for lite).
    Every paper resolution is a multiple of 32, so the squares need no padding."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import depth_model
    model = depth_model.build(model_name)
    model.load_state_dict(torch.load(checkpoint, map_location="cpu")["model"])
    model.eval()

    def teacher(rgb: np.ndarray) -> np.ndarray:
        h, w = rgb.shape[:2]
        if h % multiple or w % multiple:
            raise ValueError(f"teacher input {h}x{w} is not a multiple of {multiple}")
        x = torch.from_numpy(np.ascontiguousarray(rgb)).permute(2, 0, 1)[None]
        return model.predict(x.contiguous(memory_format=torch.channels_last))[0, 0].numpy()

    return teacher


def label_folder(photos: Path, out: Path, teacher: Teacher, resolutions: Sequence[int]):
    from PIL import Image, ImageOps  # Debian's python3-pil
    out.mkdir(parents=True, exist_ok=True)
    names = sorted(p for p in photos.rglob("*") if p.suffix.lower() in (".jpg", ".jpeg", ".png"))
    for i, path in enumerate(names):
        stem = "_".join(path.relative_to(photos).with_suffix("").parts)
        target = out / f"{stem}.npy"
        if target.exists():
            continue  # resumable: finished photos are kept
        rgb = np.asarray(ImageOps.exif_transpose(Image.open(path)).convert("RGB"), dtype=np.float32) / 255.0
        np.save(target, pseudo_ground_truth(rgb, teacher, resolutions))
        link = out / f"{stem}{path.suffix.lower()}"
        if not link.exists():
            link.symlink_to(path.resolve())
        print(f"[{i + 1}/{len(names)}] {path} -> {target}", flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--photos", required=True, help="folder of photos (searched recursively)")
    p.add_argument("--out", required=True, help="output folder: NAME.npy pseudo-labels + photo links")
    p.add_argument("--teacher-checkpoint", required=True, help="train_depth.py checkpoint.pt of the teacher")
    p.add_argument("--teacher-model", default="heavy")
    p.add_argument("--resolutions", default=",".join(map(str, PAPER_RESOLUTIONS)),
                   help="comma-separated square sides")
    p.add_argument("--threads", type=int, default=1)
    args = p.parse_args(argv)
    torch.set_num_threads(args.threads)
    resolutions = [int(v) for v in args.resolutions.split(",")]
    label_folder(Path(args.photos), Path(args.out),
                 network_teacher(args.teacher_checkpoint, args.teacher_model), resolutions)


if __name__ == "__main__":
    main()

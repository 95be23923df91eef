"""Depth training on a lent GPU machine, in runs of at most ten minutes that resume each
other: pack what the runs need here, train there, bring the checkpoints back.

    # here: the photos (downscaled), the ordinal set, each run's checkpoint and the script
    /usr/bin/python3 training/gpu_run.py pack --run lite:training/runs/lite-gpu --run heavy:training/runs/heavy-gpu
    # there (the device tool's `run`, carry ["carry"]): bash carry/train.sh
    # here again: the files that came back into the run folders
    /usr/bin/python3 training/gpu_run.py unpack FILES_AT --run lite:training/runs/lite-gpu --run heavy:training/runs/heavy-gpu

The GPU machine gets only the working tree and the carried folder (64 MiB in all), not
../shared: `pack` writes every photo at PHOTO_LONG_SIDE (JPEG) under carry/photos with the
same folder and file names, so the train/validation splits are the same there, and the
ordinal set with its points scaled to those sizes. The runs train side by side on the one
GPU, the machine's cores shared out among their DataLoader workers that make the scenes;
the GPU outruns the scene renderer, so each scene batch trains --scene-reuse steps
(augmented after the first). --minutes stops each run validated and checkpointed inside
the command's limit; validation measures an exponential moving average of the weights
(--ema). Checkpoints cross slim: no Adam moments, the average as the weights, in half
precision (a returned file may have 16 MiB, all of them 64 MiB; heavy's weights alone are
25 MB in fp32): the run resumes with those weights, its step, schedule and learning rate,
and Adam's moments start again. `unpack` puts checkpoint.pt (and best.pt, when the GPU run
beat the best so far) into each run folder and appends the run's log to its train.log, so
the next `pack` resumes where the GPU stopped, here or there.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

from PIL import Image, ImageOps

sys.path.insert(0, str(Path(__file__).resolve().parent))
import photo_folder  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PHOTO_LONG_SIDE = 384
TRANSFER_LIMIT = 64 * 2 ** 20   # the device tool's working tree, carried folder included
ORDINAL = ROOT / "training" / "ordinal" / "ordinal.json"


def slim_checkpoint(source: Path, target: Path):
    """The checkpoint without Adam's moments, with the learning rate, and its floating-point
    weights (the average's, when the run keeps one) in half precision where they fit: what
    crosses to the GPU machine and back."""
    import torch
    ckpt = torch.load(source, map_location="cpu", weights_only=False)  # our own file, from any torch
    slim = {k: v for k, v in ckpt.items() if k != "optimiser"}
    # With a weight average (train_depth.py --ema) the average crosses as the weights: two
    # sets would not fit (heavy's alone is 12.6 MB in fp16), and a run resumed from its
    # average, the average restarting there, loses nothing worth the bytes.
    weights = slim.pop("ema", ckpt["model"])
    slim["model"] = {name: half_if_exact_enough(t) for name, t in weights.items()}
    if "optimiser" in ckpt:
        slim["lr"] = ckpt["optimiser"]["param_groups"][0]["lr"]
    torch.save(slim, target)


def half_if_exact_enough(tensor):
    """fp16 for a float tensor within fp16's range (BatchNorm variances can leave it)."""
    import torch
    if tensor.dtype != torch.float32 or tensor.abs().max() > 6e4:
        return tensor
    return tensor.half()


def pack_photos(out: Path):
    """Every photo at most PHOTO_LONG_SIDE, as JPEG under its own relative name; returns
    {relative name: (scale x, scale y, new width, new height)}."""
    root = photo_folder.photo_root()
    sizes = {}
    for path in photo_folder.list_photos():
        rel = path.relative_to(root).as_posix()
        with Image.open(path) as image:
            image = ImageOps.exif_transpose(image).convert("RGB")
        scale = min(1.0, PHOTO_LONG_SIDE / max(image.size))
        small = image.resize((round(image.width * scale), round(image.height * scale)), Image.LANCZOS)
        target = out / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        small.save(target, format="JPEG", quality=85)  # keeps the name, and so the split
        sizes[rel] = (small.width / image.width, small.height / image.height, small.width, small.height)
    return sizes


def scaled_ordinal_set(ordinal: Path, sizes) -> dict:
    data = json.loads(Path(ordinal).read_text())
    for entry in data["photos"]:
        sx, sy, w, h = sizes[entry["photo"]]
        entry["width"], entry["height"] = w, h
        for pair in entry["pairs"]:
            for key in ("a", "b"):
                x, y = pair[key]
                pair[key] = [min((x + 0.5) * sx - 0.5, w - 1), min((y + 0.5) * sy - 0.5, h - 1)]
    return data


def parse_runs(specs):
    """--run MODEL:DIR, repeated: [(model, Path)]."""
    runs = []
    for spec in specs:
        model, sep, folder = spec.partition(":")
        if not sep or not folder:
            raise SystemExit(f"--run {spec}: expected MODEL:DIR, e.g. lite:training/runs/lite-gpu")
        runs.append((model, Path(folder)))
    if len({model for model, _ in runs}) != len(runs):
        raise SystemExit("--run: one run per model")
    return runs


def train_script(args, models) -> str:
    """The shell script the GPU machine runs from the repository's root: every run's
    training side by side, then its slim checkpoint, best weights and log into $OUT/MODEL/.
    A first run starts from the bundled weights; later ones resume the carried checkpoint
    (--init is then ignored)."""
    c, workers = args.carry, max(1, args.workers // len(models))
    lines = ["#!/bin/bash", "# written by training/gpu_run.py pack", "set -u",
             f"export AMPI_PHOTO_ROOT={c}/photos PYTHONUNBUFFERED=1", "pids=()"]
    for model in models:
        lines.append(
            f"{args.python} training/train_depth.py --model {model} --run {c}/{model} --data scenes "
            f"--size {args.size} --batch {args.batch} --init weights/depth_{model}.ampw --steps 10000000 "
            f"--device {args.device} --threads {args.threads} --workers {workers} --scene-reuse {args.scene_reuse} "
            f"--ema {args.ema} "
            f"--minutes {args.minutes} --val-every {args.val_every} --val-count {args.val_count} "
            f"--checkpoint-every {args.val_every} --ordinal {c}/ordinal.json --ordinal-batch {args.ordinal_batch} "
            f"> {c}/{model}/console.txt 2>&1 & pids+=($!)")
    lines.append("status=0; for pid in \"${pids[@]}\"; do wait $pid || status=1; done")
    for model in models:
        lines += [f"mkdir -p $OUT/{model}; tail -n 20 {c}/{model}/console.txt",
                  f"cp {c}/{model}/train.log $OUT/{model}/ 2>/dev/null",
                  f"[ -f {c}/{model}/checkpoint.pt ] && {args.python} training/gpu_run.py slim "
                  f"{c}/{model}/checkpoint.pt $OUT/{model}/checkpoint.pt",
                  f"[ -f {c}/{model}/best.pt ] && {args.python} training/gpu_run.py slim "
                  f"{c}/{model}/best.pt $OUT/{model}/best.pt"]
    lines.append("exit $status")
    return "\n".join(lines) + "\n"


def cmd_pack(args):
    carry, runs = Path(args.carry), parse_runs(args.run)
    if carry.exists():
        shutil.rmtree(carry)
    sizes = pack_photos(carry / "photos")
    (carry / "ordinal.json").write_text(json.dumps(scaled_ordinal_set(args.ordinal, sizes)))
    for model, run in runs:
        (carry / model).mkdir(parents=True)
        if (run / "checkpoint.pt").exists():  # best.pt stays here: the GPU writes one only if it beats it
            slim_checkpoint(run / "checkpoint.pt", carry / model / "checkpoint.pt")
    (carry / "train.sh").write_text(train_script(args, [model for model, _ in runs]))
    carried = sum(f.stat().st_size for f in carry.rglob("*") if f.is_file())
    tree = tracked_bytes()
    print(f"{carry}: {len(sizes)} photos, the ordinal set, {len(runs)} runs; {carried / 2 ** 20:.1f} MiB, "
          f"{(carried + tree) / 2 ** 20:.1f} MiB with the working tree")
    if carried + tree > TRANSFER_LIMIT:
        raise SystemExit(f"{carry}: the working tree and carry/ come to more than the device tool's "
                         f"{TRANSFER_LIMIT // 2 ** 20} MiB")
    print(f"device command (carry [\"{args.carry}\"]):")
    print(f"bash {args.carry}/train.sh")


def tracked_bytes() -> int:
    import subprocess
    names = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return sum((ROOT / n).stat().st_size for n in names.decode().split("\0") if n and (ROOT / n).is_file())


def cmd_slim(args):
    slim_checkpoint(Path(args.source), Path(args.target))


def cmd_unpack(args):
    came_back, runs = Path(args.files_at), parse_runs(args.run)
    for model, _ in runs:
        missing = [name for name in ("checkpoint.pt", "train.log") if not (came_back / model / name).exists()]
        if missing:
            raise SystemExit(f"{came_back}/{model}: {', '.join(missing)} did not come back; "
                             f"the run folders are unchanged")
    for model, run in runs:
        run.mkdir(parents=True, exist_ok=True)
        copied = [name for name in ("checkpoint.pt", "best.pt") if (came_back / model / name).exists()]
        for name in copied:
            shutil.copyfile(came_back / model / name, run / name)  # writable, unlike what came back
        with open(run / "train.log", "a") as log:
            log.write((came_back / model / "train.log").read_text())
        print(f"{run}: {' and '.join(copied)} from {came_back}/{model}, its log appended to train.log")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    pack = sub.add_parser("pack", help="photos, ordinal set and checkpoint into carry/")
    pack.add_argument("--run", action="append", required=True,
                      help="MODEL:DIR, repeatable: a model to train and its run folder (may be new)")
    pack.add_argument("--carry", default="carry", help="the folder to fill, relative to the repository root")
    pack.add_argument("--ordinal", default=str(ORDINAL))
    pack.add_argument("--device", default="cuda")
    pack.add_argument("--python", default="python3", help="the GPU machine's Python (the one with PyTorch)")
    pack.add_argument("--threads", type=int, default=1, help="CPU threads of each training process")
    pack.add_argument("--workers", type=int, default=15,
                      help="scene-making processes, shared out among the runs (the machine has 16 cores)")
    pack.add_argument("--scene-reuse", type=int, default=4, help="steps each rendered scene batch trains")
    pack.add_argument("--ema", type=float, default=0.999,
                      help="decay of the weight average that validation measures (0: none)")
    pack.add_argument("--val-count", type=int, default=32)
    pack.add_argument("--size", default="256x192")
    pack.add_argument("--batch", type=int, default=48)
    pack.add_argument("--ordinal-batch", type=int, default=16)
    pack.add_argument("--minutes", type=float, default=8.0, help="training time of one device run")
    pack.add_argument("--val-every", type=int, default=500)
    unpack = sub.add_parser("unpack", help="the files that came back into the run folder")
    unpack.add_argument("files_at")
    unpack.add_argument("--run", action="append", required=True, help="MODEL:DIR, as given to pack")
    slim = sub.add_parser("slim", help="a checkpoint without Adam's moments")
    slim.add_argument("source")
    slim.add_argument("target")
    args = p.parse_args()
    {"pack": cmd_pack, "unpack": cmd_unpack, "slim": cmd_slim}[args.command](args)


if __name__ == "__main__":
    main()

"""Depth training on a lent GPU machine, in runs of at most ten minutes that resume each
other: pack what the run needs here, train there, bring the checkpoint back.

    # here: the photos (downscaled), the ordinal set and the run's checkpoint into carry/
    /usr/bin/python3 training/gpu_run.py pack --run training/runs/lite-256
    # there (the device tool's `run`, carry ["carry"]): the command `pack` prints
    # here again: the files that came back into the run folder
    /usr/bin/python3 training/gpu_run.py unpack FILES_AT --run training/runs/lite-256

The GPU machine gets only the working tree and the carried folder (64 MiB in all), not
../shared: `pack` writes every photo at PHOTO_LONG_SIDE (JPEG) under carry/photos with the
same folder and file names, so the train/validation splits are the same there, and the
ordinal set with its points scaled to those sizes. Scenes are made by DataLoader workers on the machine's cores while the GPU
trains; --minutes stops the run validated and checkpointed inside the command's limit.
Checkpoints cross slim (no Adam moments: the repository's tracked files already take
about 44 of the 64 MiB): the run resumes with its weights, step, schedule and learning
rate, and Adam's moments start again. `unpack` puts checkpoint.pt (and best.pt, when the
GPU run beat the best so far) into the run folder and appends the run's log to its
train.log, so the next `pack` resumes where the GPU stopped, here or there.
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
    """The checkpoint without Adam's moments (two thirds of its size), with the learning
    rate: what crosses to the GPU machine and back (16 MiB a returned file at most)."""
    import torch
    ckpt = torch.load(source, map_location="cpu")
    slim = {k: v for k, v in ckpt.items() if k != "optimiser"}
    if "optimiser" in ckpt:
        slim["lr"] = ckpt["optimiser"]["param_groups"][0]["lr"]
    torch.save(slim, target)


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


def device_command(args) -> str:
    """The command for the GPU machine, run from the repository's root. A first run starts
    from the bundled weights; later ones resume the carried checkpoint (--init is then
    ignored)."""
    c = args.carry
    return (f"AMPI_PHOTO_ROOT={c}/photos PYTHONUNBUFFERED=1 {args.python} training/train_depth.py "
            f"--model {args.model} --run {c}/run --data scenes --size {args.size} --batch {args.batch} "
            f"--init weights/depth_{args.model}.ampw --steps 10000000 --device {args.device} "
            f"--threads {args.threads} --workers {args.workers} --minutes {args.minutes} "
            f"--val-every {args.val_every} --val-count {args.val_count} --checkpoint-every {args.val_every} "
            f"--ordinal {c}/ordinal.json --ordinal-batch {args.ordinal_batch} "
            f"&& {args.python} training/gpu_run.py slim {c}/run/checkpoint.pt $OUT/checkpoint.pt "
            f"&& cp {c}/run/train.log $OUT/ && if [ -f {c}/run/best.pt ]; then cp {c}/run/best.pt $OUT/; fi")


def cmd_pack(args):
    carry = Path(args.carry)
    if carry.exists():
        shutil.rmtree(carry)
    (carry / "run").mkdir(parents=True)
    sizes = pack_photos(carry / "photos")
    (carry / "ordinal.json").write_text(json.dumps(scaled_ordinal_set(args.ordinal, sizes)))
    run = Path(args.run)
    if (run / "checkpoint.pt").exists():  # best.pt stays here: the GPU writes one only if it beats it
        slim_checkpoint(run / "checkpoint.pt", carry / "run" / "checkpoint.pt")
    carried = sum(f.stat().st_size for f in carry.rglob("*") if f.is_file())
    tree = tracked_bytes()
    print(f"{carry}: {len(sizes)} photos, the ordinal set, {run}'s checkpoint; {carried / 2 ** 20:.1f} MiB, "
          f"{(carried + tree) / 2 ** 20:.1f} MiB with the working tree")
    if carried + tree > TRANSFER_LIMIT:
        raise SystemExit(f"{carry}: the working tree and carry/ come to more than the device tool's "
                         f"{TRANSFER_LIMIT // 2 ** 20} MiB")
    print(f"device command (carry [\"{args.carry}\"]):")
    print(device_command(args))


def tracked_bytes() -> int:
    import subprocess
    names = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return sum((ROOT / n).stat().st_size for n in names.decode().split("\0") if n and (ROOT / n).is_file())


def cmd_slim(args):
    slim_checkpoint(Path(args.source), Path(args.target))


def cmd_unpack(args):
    came_back, run = Path(args.files_at), Path(args.run)
    missing = [name for name in ("checkpoint.pt", "train.log") if not (came_back / name).exists()]
    if missing:
        raise SystemExit(f"{came_back}: {', '.join(missing)} did not come back; the run folder is unchanged")
    run.mkdir(parents=True, exist_ok=True)
    copied = [name for name in ("checkpoint.pt", "best.pt") if (came_back / name).exists()]
    for name in copied:
        shutil.copy2(came_back / name, run / name)
    with open(run / "train.log", "a") as log:
        log.write((came_back / "train.log").read_text())
    print(f"{run}: {' and '.join(copied)} from {came_back}, its log appended to train.log")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    pack = sub.add_parser("pack", help="photos, ordinal set and checkpoint into carry/")
    pack.add_argument("--run", required=True, help="the run folder whose checkpoint to carry (may be new)")
    pack.add_argument("--carry", default="carry", help="the folder to fill, relative to the repository root")
    pack.add_argument("--ordinal", default=str(ORDINAL))
    pack.add_argument("--model", default="lite")
    pack.add_argument("--device", default="cuda")
    pack.add_argument("--python", default="python3", help="the GPU machine's Python (the one with PyTorch)")
    pack.add_argument("--threads", type=int, default=4)
    pack.add_argument("--workers", type=int, default=14, help="scene-making processes (the machine has 16 cores)")
    pack.add_argument("--val-count", type=int, default=32)
    pack.add_argument("--size", default="256x192")
    pack.add_argument("--batch", type=int, default=48)
    pack.add_argument("--ordinal-batch", type=int, default=16)
    pack.add_argument("--minutes", type=float, default=8.5, help="training time of one device run")
    pack.add_argument("--val-every", type=int, default=500)
    unpack = sub.add_parser("unpack", help="the files that came back into the run folder")
    unpack.add_argument("files_at")
    unpack.add_argument("--run", required=True)
    slim = sub.add_parser("slim", help="a checkpoint without Adam's moments")
    slim.add_argument("source")
    slim.add_argument("target")
    args = p.parse_args()
    {"pack": cmd_pack, "unpack": cmd_unpack, "slim": cmd_slim}[args.command](args)


if __name__ == "__main__":
    main()

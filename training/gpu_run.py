"""Training on a lent GPU machine, in runs of at most ten minutes that resume each other:
pack what the runs need here, train there, bring the checkpoints back. A run trains a
depth network (lite, heavy: train_depth.py) or the inpainting network (inpaint:
train_inpaint.py).

    # here: the photos (downscaled), the ordinal set, plane maps, each run's checkpoint, the script
    /usr/bin/python3 training/gpu_run.py pack --run lite:training/runs/lite-gpu --run inpaint:training/runs/inpaint-gpu
    # there (the device tool's `run`, carry ["carry"]): bash carry/train.sh
    # here again: the files that came back into the run folders
    /usr/bin/python3 training/gpu_run.py unpack FILES_AT --run lite:training/runs/lite-gpu \\
        --run inpaint:training/runs/inpaint-gpu

The GPU machine gets only the working tree and the carried folder (64 MiB in all), not
../shared: `pack` writes every photo at PHOTO_LONG_SIDE (JPEG) under carry/photos with the
same folder and file names, so the train/validation splits are the same there; train.sh
first scales the ordinal set's points to those sizes there (`gpu_run.py ordinal`), from
the set that travels with the working tree, so that only one copy of it takes room. The
inpainting run trains on the same photos, so at most 384 px there against
inpaint_data.MAX_SIDE = 768 here: a photo of 768 px or more is seen at half the scale. For each photo with a cached disparity map
(--disparity-dir) it gets the plane map its slicing would make of that map at the carried
size (inpaint_data.write_planes; the maps themselves would not fit); the others get the
stand-in there as here. `pack` prints what each part of the transfer takes and fails,
naming them, when the working tree and carry/ come to more than 64 MiB.

With --teacher WEIGHTS.ampw the depth runs self-distil as they do here (train_depth.py
--teacher-labels). The labels would not fit the transfer, so the GPU machine makes them
before training: the teacher's ensemble at long sides 192-320 of the carried photos
(distill.py --keep-aspect, on the GPU). Here `ampi distill` labels the full-size photos,
area-shrunk to 320 px, so the two label sets differ by what the 384-px JPEG loses.

The runs train side by side on the one GPU, the machine's cores shared out equally among
their DataLoader workers (scenes for depth, crops and their prefill for inpainting); the
GPU outruns the scene renderer, so each depth scene batch trains --scene-reuse steps
(augmented after the first). --minutes stops each run validated and checkpointed; train.sh
cuts it shorter when the teacher's labels have left less of the call (--call-seconds, the
device tool's limit) than the training, the last validation and the hand-back need. Depth
validation measures an exponential moving average of the weights (--ema); --lr-decay
cosine --decay-steps N gives the depth runs a learning rate that falls with the step
(train_depth.cosine_lr) instead of x0.2 on a plateau.

Checkpoints cross slim, without Adam's moments (a returned file may have 16 MiB, all of
them 64 MiB). A depth checkpoint carries the average as the weights, in half precision
(heavy's weights alone are 25 MB in fp32), its step, schedule and learning rate; an
inpainting checkpoint keeps its two small networks in fp32. Each run resumes with those
weights and its step, and Adam's moments start again. `unpack` puts the checkpoint
(checkpoint.pt; inpainting's last.pt) and best.pt, when the GPU run beat the best so far,
into each run folder and appends the run's logs to its own (train.log; inpainting's
log.csv too, without a second header), so the next `pack` resumes where the GPU stopped,
here or there.
"""
from __future__ import annotations

import argparse
import json
import shlex
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from PIL import Image, ImageOps

sys.path.insert(0, str(Path(__file__).resolve().parent))
import depth_model  # noqa: E402
import inpaint_data  # noqa: E402
import photo_folder  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PHOTO_LONG_SIDE = 384
PHOTO_QUALITY = 65   # JPEG: the 560 photos take 9.5 MiB (10.4 at 70), against the transfer limit
TRANSFER_LIMIT = 64 * 2 ** 20   # the device tool's working tree, carried folder included
ORDINAL = ROOT / "training" / "ordinal" / "ordinal.json.gz"
INPAINT = "inpaint"
TEACHER_LABELS = "teacher"   # the teacher's label folder under the carried folder, made there
NETWORKS = (*depth_model.ARCHITECTURES, INPAINT)   # what --run NAME:DIR may name
HANDBACK_SECONDS = 60   # of a device call: the last validation, the slim checkpoints, the logs
INPAINT_ARGS = "--batch 32 --crop 96 --lr-g 4e-4 --lr-d 2e-4 --validate-every 250 --checkpoint-every 250"


@dataclass(frozen=True)
class RunFiles:
    checkpoint: str    # the resumable checkpoint in the run folder
    logs: tuple        # the logs unpack appends to the run folder's own


DEPTH_FILES = RunFiles("checkpoint.pt", ("train.log",))
INPAINT_FILES = RunFiles("last.pt", ("train.log", "log.csv"))


def run_files(name: str) -> RunFiles:
    return INPAINT_FILES if name == INPAINT else DEPTH_FILES


# ---- checkpoints ----------------------------------------------------------------------------

def slim_checkpoint(source: Path, target: Path):
    """What crosses to the GPU machine and back: the checkpoint without Adam's moments (an
    inpainting one has a generator, a depth one a model)."""
    import torch
    ckpt = torch.load(source, map_location="cpu", weights_only=False)  # our own file, from any torch
    torch.save(slim_inpaint(ckpt) if "generator" in ckpt else slim_depth(ckpt), target)


def slim_depth(ckpt: dict) -> dict:
    """A depth checkpoint with the learning rate and its floating-point weights (the
    average's, when the run keeps one) in half precision where they fit."""
    slim = {k: v for k, v in ckpt.items() if k != "optimiser"}
    # With a weight average (train_depth.py --ema) the average crosses as the weights: two
    # sets would not fit (heavy's alone is 12.6 MB in fp16), and a run resumed from its
    # average, the average restarting there, loses nothing worth the bytes.
    weights = slim.pop("ema", ckpt["model"])
    slim["model"] = {name: half_if_exact_enough(t) for name, t in weights.items()}
    if "optimiser" in ckpt:
        slim["lr"] = ckpt["optimiser"]["param_groups"][0]["lr"]
    return slim


def slim_inpaint(ckpt: dict) -> dict:
    """An inpainting checkpoint without its optimisers. Both networks stay fp32: together
    they are 1.6 MB, so half precision would save little and cost the generator's small
    residual its exactness."""
    return {k: v for k, v in ckpt.items() if k not in ("opt_g", "opt_d")}


def half_if_exact_enough(tensor):
    """fp16 for a float tensor within fp16's range (BatchNorm variances can leave it)."""
    import torch
    if tensor.dtype != torch.float32 or tensor.abs().max() > 6e4:
        return tensor
    return tensor.half()


# ---- pack -----------------------------------------------------------------------------------

def pack_photos(out: Path):
    """Every photo at most PHOTO_LONG_SIDE, as JPEG under its own relative name; returns
    {relative name: (width, height) there}."""
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
        small.save(target, format="JPEG", quality=PHOTO_QUALITY)  # keeps the name, and so the split
        sizes[rel] = small.size
    return sizes


def scaled_ordinal_set(ordinal: Path, photos_root: Path) -> dict:
    """The ordinal set for the carried photos under photos_root: its points scaled from
    each photo's size in the set (upright, as labelled) to the carried one (to a tenth of
    a pixel), and only what training reads (the ordered pairs' points and labels)."""
    data = photo_folder.read_json(ordinal)
    photos = []
    for entry in data["photos"]:
        try:
            with Image.open(photos_root / entry["photo"]) as carried:
                w, h = carried.size
        except OSError:
            raise SystemExit(photo_folder.missing_photo(ordinal, entry["photo"], photos_root))
        sx, sy = w / entry["width"], h / entry["height"]

        def scaled(point):  # pixel centres scaled, kept inside the carried photo
            x, y = point
            return [round(min((x + 0.5) * sx - 0.5, w - 1), 1), round(min((y + 0.5) * sy - 0.5, h - 1), 1)]

        pairs = [{"label": pair["label"], "a": scaled(pair["a"]), "b": scaled(pair["b"])}
                 for pair in entry["pairs"] if pair["label"] in ("A", "B")]
        photos.append({**entry, "width": w, "height": h, "pairs": pairs})
    return {"photos": photos}


def pack_planes(out: Path, sizes, disparity_dir: str) -> int:
    """The plane map of every photo with a cached disparity map, at its carried size (the
    maps themselves would take several times the room); returns how many."""
    count = 0
    for rel, (w, h) in sizes.items():
        source = Path(inpaint_data.disparity_path(disparity_dir, rel))
        if source.exists():
            inpaint_data.write_planes(str(source), (w, h), inpaint_data.disparity_path(str(out), rel))
            count += 1
    return count


def parse_runs(specs):
    """--run NAME:DIR, repeated: [(name, Path)]."""
    runs = []
    for spec in specs:
        name, sep, folder = spec.partition(":")
        if not sep or not folder or name not in NETWORKS:
            raise SystemExit(f"--run {spec}: expected NAME:DIR with NAME one of {', '.join(NETWORKS)}, "
                             f"e.g. lite:training/runs/lite-gpu")
        runs.append((name, Path(folder)))
    if len({name for name, _ in runs}) != len(runs):
        raise SystemExit("--run: one run per network")
    return runs


def depth_command(args, model: str, workers: int) -> str:
    """A first run starts from the bundled weights; later ones resume the carried
    checkpoint (--init is then ignored)."""
    c = args.carry
    lr = f" --lr {args.lr:g}" if args.lr is not None else ""   # else train_depth.py's default
    decay = f" --lr-decay cosine --decay-steps {args.decay_steps}" if args.lr_decay == "cosine" else ""
    return (f"{args.python} training/train_depth.py --model {model} --run {c}/{model} --data scenes "
            f"--size {args.size} --batch {args.batch} --init weights/depth_{model}.ampw --steps 10000000 "
            f"--device {args.device} --threads {args.threads} --workers {workers} --scene-reuse {args.scene_reuse} "
            f"--ema {args.ema}{lr}{decay} "
            f"--minutes $minutes --val-every {args.val_every} --val-count {args.val_count} "
            f"--checkpoint-every {args.val_every} --ordinal {c}/ordinal.json --ordinal-batch {args.ordinal_batch} "
            f"--rank-weight {args.rank_weight:g} --loss {args.loss}{' --bf16' if args.bf16 else ''}"
            + (f" --teacher-labels {c}/{TEACHER_LABELS} --teacher-weight {args.teacher_weight:g}" if args.teacher else ""))


def teacher_command(args, weights: str) -> str:
    """The teacher's labels, made there on the GPU by distill.py (the engine is not built
    on that machine): its keep-aspect ensemble of the carried photos, the folder
    train_depth.py --teacher-labels reads."""
    c = args.carry
    return (f"{args.python} training/distill.py --photos {c}/photos --out {c}/{TEACHER_LABELS} "
            f"--teacher-checkpoint {weights} --resolutions {args.teacher_resolutions} --keep-aspect "
            f"--device {args.device} --threads {args.threads}")


def inpaint_command(args, workers: int) -> str:
    """A first run starts from the bundled generator, with the bundled lite depth
    network's encoder as its perceptual features; --inpaint-args come last, so they
    override."""
    c = args.carry
    return (f"{args.python} training/train_inpaint.py --run-dir {c}/{INPAINT} --photos {c}/photos "
            f"--planes-dir {c}/inpaint_planes --init weights/inpaint.ampw --perceptual weights/depth_lite.ampw "
            f"--device {args.device} --threads {args.threads} --workers {workers} --minutes $minutes "
            f"{shlex.join(shlex.split(args.inpaint_args))}")


def train_script(args, names, ordinal, teacher_weights) -> str:
    """The shell script the GPU machine runs from the repository's root: the ordinal set
    scaled to the carried photos first, the teacher's labels next (with --teacher), then
    every run's training side by side, then its slim checkpoint, best weights and logs
    into $OUT/NAME/. The training gets --minutes or
    what the call has left after the teacher and before the hand-back, whichever is less:
    a call the device tool stops at its limit brings nothing back."""
    c, workers = args.carry, max(1, args.workers // len(names))
    lines = ["#!/bin/bash", "# written by training/gpu_run.py pack", "set -u",
             f"export AMPI_PHOTO_ROOT={c}/photos PYTHONUNBUFFERED=1", "pids=()",
             f"deadline=$(( $(date +%s) + {args.call_seconds - HANDBACK_SECONDS} ))",
             f"{args.python} training/gpu_run.py ordinal {ordinal} {c}/photos {c}/ordinal.json || exit 1"]
    if teacher_weights:
        lines.append(f"{teacher_command(args, teacher_weights)} > {c}/teacher.txt 2>&1 "
                     f"|| {{ tail -n 20 {c}/teacher.txt; exit 1; }}")
    lines += [f"minutes=$(awk -v cap={args.minutes:g} -v left=$(( deadline - $(date +%s) )) "
              "'BEGIN { m = left / 60; if (m > cap) m = cap; printf \"%.2f\", m }')",
              "awk \"BEGIN { exit !($minutes > 0) }\" || { echo \"train.sh: no time left to train\"; exit 1; }",
              "echo \"train.sh: training for $minutes minutes\""]
    for name in names:
        command = inpaint_command(args, workers) if name == INPAINT else depth_command(args, name, workers)
        lines.append(f"{command} > {c}/{name}/console.txt 2>&1 & pids+=($!)")
    lines.append("status=0; for pid in \"${pids[@]}\"; do wait $pid || status=1; done")
    for name in names:
        files = run_files(name)
        lines += [f"mkdir -p $OUT/{name}; tail -n 20 {c}/{name}/console.txt"]
        lines += [f"cp {c}/{name}/{log} $OUT/{name}/ 2>/dev/null" for log in files.logs]
        lines += [f"[ -f {c}/{name}/{ckpt} ] && {args.python} training/gpu_run.py slim "
                  f"{c}/{name}/{ckpt} $OUT/{name}/{ckpt}" for ckpt in (files.checkpoint, "best.pt")]
    lines.append("exit $status")
    return "\n".join(lines) + "\n"


def size_of(path: Path) -> int:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file()) if path.is_dir() else path.stat().st_size


def cmd_pack(args):
    carry, runs = Path(args.carry), parse_runs(args.run)
    if args.lr_decay == "cosine" and args.decay_steps <= 0:
        raise SystemExit("gpu_run.py pack: --lr-decay cosine needs --decay-steps N (N > 0)")
    if args.call_seconds <= HANDBACK_SECONDS:
        raise SystemExit(f"gpu_run.py pack: --call-seconds {args.call_seconds} leaves no time to train "
                         f"(the hand-back takes {HANDBACK_SECONDS})")
    if args.teacher and all(name == INPAINT for name, _ in runs):
        raise SystemExit("gpu_run.py pack: --teacher labels photos for depth runs; give a --run lite:DIR or heavy:DIR")
    if carry.exists():
        shutil.rmtree(carry)
    sizes = pack_photos(carry / "photos")
    planes = pack_planes(carry / "inpaint_planes", sizes, args.disparity_dir) if INPAINT in dict(runs) else 0
    tracked = tracked_files()
    ordinal = carried_file(Path(args.ordinal), carry / "ordinal_set", f"{args.carry}/ordinal_set", tracked)
    scaled_ordinal_set(Path(args.ordinal), carry / "photos")   # fails here what would fail there
    teacher_weights = carried_teacher(args, carry, tracked) if args.teacher else None
    for name, run in runs:
        (carry / name).mkdir(parents=True)
        checkpoint = run_files(name).checkpoint
        if (run / checkpoint).exists():  # best.pt stays here: the GPU writes one only if it beats it
            slim_checkpoint(run / checkpoint, carry / name / checkpoint)
    (carry / "train.sh").write_text(train_script(args, [name for name, _ in runs], ordinal, teacher_weights))
    parts = {part.name: size_of(part) for part in sorted(carry.iterdir())}
    tree = sum(path.stat().st_size for path in tracked)
    total = tree + sum(parts.values())
    shown = f"the working tree {tree / 2 ** 20:.1f}, " + ", ".join(
        f"{name} {size / 2 ** 20:.1f}" for name, size in parts.items())
    print(f"{carry}: {len(sizes)} photos, the ordinal set, {planes} plane maps, {len(runs)} runs; "
          f"{total / 2 ** 20:.1f} MiB in all ({shown})")
    if total > TRANSFER_LIMIT:
        raise SystemExit(f"{carry}: {total / 2 ** 20:.1f} MiB in all ({shown}), more than the device tool's "
                         f"{TRANSFER_LIMIT // 2 ** 20} MiB")
    print(f"device command (carry [\"{args.carry}\"]):")
    print(f"bash {args.carry}/train.sh")


def tracked_files() -> list:
    import subprocess
    names = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    return [ROOT / n for n in names.decode().split("\0") if n and (ROOT / n).is_file()]


def carried_teacher(args, carry: Path, tracked: list) -> str:
    """The teacher's weights as the GPU machine finds them (carried_file: the bundled
    weights travel with the working tree)."""
    weights = Path(args.teacher)
    if weights.suffix != ".ampw" or not weights.is_file():
        raise SystemExit(f"--teacher {args.teacher}: expected a depth network's .ampw file (export_depth.py)")
    return carried_file(weights, carry / "teacher_weights", f"{args.carry}/teacher_weights", tracked)


def carried_file(path: Path, folder: Path, there: str, tracked: list) -> str:
    """Where the GPU machine finds the file at path, for commands run from the
    repository's root: a file of the working tree (`tracked`, as tracked_files() lists
    it) travels with it; any other is copied into folder, a folder of the carried one,
    which the GPU machine finds at `there`."""
    path = path.resolve()
    if not path.is_file():
        raise SystemExit(f"{path}: no such file to carry")
    if path in tracked:
        return path.relative_to(ROOT).as_posix()
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(path, folder / path.name)
    return f"{there}/{path.name}"


# ---- ordinal and slim (there), unpack -------------------------------------------------------

def cmd_ordinal(args):
    scaled = scaled_ordinal_set(Path(args.ordinal), Path(args.photos))
    Path(args.out).write_text(json.dumps(scaled, separators=(",", ":")))


def cmd_slim(args):
    slim_checkpoint(Path(args.source), Path(args.target))


def append_log(source: Path, target: Path):
    """source's lines at the end of target, less a first line target starts with too
    (log.csv's header)."""
    lines = source.read_text().splitlines(keepends=True)
    if lines and target.exists():
        with open(target) as existing:
            if existing.readline() == lines[0]:
                lines = lines[1:]
    with open(target, "a") as log:
        log.writelines(lines)


def cmd_unpack(args):
    came_back, runs = Path(args.files_at), parse_runs(args.run)
    for name, _ in runs:
        files = run_files(name)
        missing = [f for f in (files.checkpoint, *files.logs) if not (came_back / name / f).exists()]
        if missing:
            raise SystemExit(f"{came_back}/{name}: {', '.join(missing)} did not come back; "
                             f"the run folders are unchanged")
    for name, run in runs:
        files = run_files(name)
        run.mkdir(parents=True, exist_ok=True)
        copied = [f for f in (files.checkpoint, "best.pt") if (came_back / name / f).exists()]
        for f in copied:
            shutil.copyfile(came_back / name / f, run / f)  # writable, unlike what came back
        for log in files.logs:
            append_log(came_back / name / log, run / log)
        print(f"{run}: {' and '.join(copied)} from {came_back}/{name}, {' and '.join(files.logs)} appended")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    pack = sub.add_parser("pack", help="photos, ordinal set, plane maps and checkpoints into carry/")
    pack.add_argument("--run", action="append", required=True,
                      help="NAME:DIR, repeatable: a network to train (lite, heavy, inpaint) and its run "
                           "folder (may be new)")
    pack.add_argument("--carry", default="carry", help="the folder to fill, relative to the repository root")
    pack.add_argument("--ordinal", default=str(ORDINAL))
    pack.add_argument("--device", default="cuda")
    pack.add_argument("--python", default="python3", help="the GPU machine's Python (the one with PyTorch)")
    pack.add_argument("--threads", type=int, default=1, help="CPU threads of each training process")
    pack.add_argument("--workers", type=int, default=15,
                      help="batch-making processes, shared out equally among the runs (the machine has 16 cores)")
    pack.add_argument("--minutes", type=float, default=8.0, help="training time of one device run")
    pack.add_argument("--call-seconds", type=int, default=600,
                      help="the device call's limit (its timeout_s): train.sh trains less when the teacher "
                           f"leaves less than --minutes plus {HANDBACK_SECONDS} s for the hand-back")
    depth = pack.add_argument_group("depth runs")
    depth.add_argument("--scene-reuse", type=int, default=4, help="steps each rendered scene batch trains")
    depth.add_argument("--ema", type=float, default=0.999,
                       help="decay of the weight average that validation measures (0: none)")
    depth.add_argument("--lr", type=float,
                       help="the depth runs' (starting) learning rate (default: train_depth.py's own)")
    depth.add_argument("--lr-decay", choices=("none", "cosine"), default="none",
                       help="none: lr x0.2 on a plateau; cosine: lr falls by the step (train_depth.py)")
    depth.add_argument("--decay-steps", type=int, default=0,
                       help="with --lr-decay cosine: the step (from the run's start) where lr reaches its floor")
    depth.add_argument("--val-count", type=int, default=32)
    depth.add_argument("--loss", choices=("paper", "invariant"), default="paper", help="train_depth.py --loss")
    depth.add_argument("--bf16", action="store_true",
                       help="train_depth.py --bf16: bfloat16 autocast (measured on this CPU, not yet on a GPU)")
    depth.add_argument("--size", default="256x192")
    depth.add_argument("--batch", type=int, default=48)
    depth.add_argument("--ordinal-batch", type=int, default=16)
    depth.add_argument("--rank-weight", type=float, default=8.0,
                       help="weight of the ranking loss on the photos' pairs (the bundled lite's run: 8)")
    depth.add_argument("--val-every", type=int, default=500)
    depth.add_argument("--teacher", help="self-distillation: a depth .ampw whose keep-aspect ensemble "
                                         "labels the carried photos there, for --teacher-labels (e.g. "
                                         "weights/depth_lite.ampw)")
    depth.add_argument("--teacher-weight", type=float, default=1.0, help="weight of the loss on the teacher's labels")
    depth.add_argument("--teacher-resolutions", default="192,224,256,288,320",
                       help="the ensemble's long sides (those of the bundled lite's teacher, training/DEPTH.md)")
    inpaint = pack.add_argument_group("the inpainting run")
    inpaint.add_argument("--disparity-dir", default=inpaint_data.DEFAULT_DISPARITY_DIR,
                         help="cached disparity maps (inpaint_data.py --write-disparity) to carry as plane maps")
    inpaint.add_argument("--inpaint-args", default=INPAINT_ARGS,
                         help="more train_inpaint.py options, one string (write --inpaint-args=\"...\"); "
                              "they override pack's")
    unpack = sub.add_parser("unpack", help="the files that came back into the run folders")
    unpack.add_argument("files_at")
    unpack.add_argument("--run", action="append", required=True, help="NAME:DIR, as given to pack")
    ordinal = sub.add_parser("ordinal", help="(train.sh, there) the ordinal set scaled to the carried photos")
    ordinal.add_argument("ordinal", help="the ordinal set (training/ordinal/ordinal.json.gz)")
    ordinal.add_argument("photos", help="the carried photos' folder, with the set's relative names")
    ordinal.add_argument("out", help="the scaled set to write, for train_depth.py --ordinal")
    slim = sub.add_parser("slim", help="a checkpoint without Adam's moments")
    slim.add_argument("source")
    slim.add_argument("target")
    args = p.parse_args(argv)
    {"pack": cmd_pack, "unpack": cmd_unpack, "ordinal": cmd_ordinal, "slim": cmd_slim}[args.command](args)


if __name__ == "__main__":
    main()

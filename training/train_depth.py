"""Trains the depth network (lite or heavy) on (image, disparity) pairs.

    /usr/bin/python3 training/train_depth.py --model lite --run training/runs/lite \
        --data scenes --size 256x192 --batch 4 --steps 20000

The paper's recipe: Adam at 1e-3, learning rate x0.2 when the validation loss plateaus,
the loss of training/losses.py on all four outputs. `--lr-decay cosine --decay-steps N`
replaces the plateau rule by a fixed curve: --lr down to --lr / 100 at step N by half a
cosine, flat after (cosine_lr). Runs are resumable: the run folder
holds `checkpoint.pt` (model, optimiser, scheduler, step, best validation loss), written
atomically every --checkpoint-every steps, `best.pt` (the weights of the best validation
loss so far: what to export), and `train.log`, one text line per logged step and per
validation (the loss and the paper's metrics, see aligned_metrics). Starting again with the same --run continues where it stopped.

Data sources (--data), all yielding (rgb, disparity) pairs, rgb in [0, 1]:
  scenes       the procedural RGB-D generator of training/scenes.py (exact disparity)
  cards        the small built-in generator of training/card_scenes.py (exact disparity)
  pairs:DIR    a folder of photos NAME.jpg|png with disparity maps NAME.npy beside them
               (what training/distill.py writes for pseudo-labelled photos)
  distilled:LABELS  a label folder of `ampi distill` (16-bit PNGs, labels.tsv naming each
               label's photo); the ordinal set's validation photos are left out
Validation uses a disjoint fixed set: scene seeds from VAL_SEED_START, or every tenth
pair by sorted name (never trained on).

Real photos (--ordinal training/ordinal/ordinal.json.gz): each step also takes
--ordinal-batch photos of the set's training split (random crops, flips; wider crops
and colour jitter with --photo-augment) with the ranking loss of their labelled pairs
(training/ordinal_data.py), weighted by --rank-weight, beside the paper's loss on the
synthetic batch; every validation also measures WHDR on the set's validation photos,
and best.pt is then the best WHDR.
--teacher-labels LABELS (an `ampi distill` folder of the photo folder) adds the paper's
loss on those photos' pseudo ground truth, cropped and flipped with them and weighted by
--teacher-weight: the paper's self-distillation, beside the scenes and the pairs.
Batches are made ahead by --workers processes (DataLoader), so the network never waits
for the scene renderer. --bf16 runs the training forward pass under bfloat16 autocast
(heads, losses, weights, Adam and validation stay fp32): 1.2-1.4x faster on a CPU with
AVX512-BF16 (training/BENCH_TRAIN.md).
"""
from __future__ import annotations

import argparse
import math
import os
import random
import sys
import time
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F

sys.path.insert(0, str(Path(__file__).resolve().parent))
import depth_model  # noqa: E402
import distill  # noqa: E402
import losses  # noqa: E402
import malloc_reuse  # noqa: E402
import ordinal_data  # noqa: E402

VAL_SEED_START = 1_000_000_000  # synthetic validation scenes; training seeds stay below
VAL_EVERY_TENTH = 10


# ---- data sources -------------------------------------------------------------------------

def to_tensors(rgb, disparity):
    """Accepts numpy (H x W x 3 uint8 or float in [0, 1]; H x W disparity) or torch
    (3 x H x W, 1 x H x W) and returns float32 tensors [3, H, W] and [1, H, W]."""
    if isinstance(rgb, np.ndarray):
        scale = 1.0 / 255.0 if rgb.dtype == np.uint8 else 1.0
        rgb = torch.from_numpy(np.ascontiguousarray(rgb)).permute(2, 0, 1).float() * scale
    if isinstance(disparity, np.ndarray):
        disparity = torch.from_numpy(np.ascontiguousarray(disparity, dtype=np.float32))
    if disparity.dim() == 2:
        disparity = disparity.unsqueeze(0)
    return rgb.float(), disparity.float()


class SceneSource:
    """Procedural scenes by seed (training/scenes.py): exact disparity, and validation seeds
    textured only with validation photos."""

    def __init__(self, size):
        import scenes  # the generator lives beside this file
        self.scenes = scenes
        self.width, self.height = size

    def sample(self, index: int, validation: bool):
        seed = (VAL_SEED_START if validation else 0) + index
        return to_tensors(*self.scenes.render_scene(seed, self.width, self.height))

    def validation_count(self, wanted: int) -> int:
        return wanted


class CardSource:
    """The small built-in generator (training/card_scenes.py): cards on a ground plane."""

    def __init__(self, size):
        import card_scenes
        self.render = card_scenes.CardScenes(*size)

    def sample(self, index: int, validation: bool):
        return to_tensors(*self.render((VAL_SEED_START if validation else 0) + index))

    def validation_count(self, wanted: int) -> int:
        return wanted


class PairFolderSource:
    """Photos with disparity maps, resized to the training size. Every tenth pair by
    sorted name is the validation split."""

    def __init__(self, pairs, size, where: str):
        self.width, self.height = size
        if not pairs:
            raise FileNotFoundError(f"{where}: no photo with a disparity map")
        pairs = sorted(pairs)
        self.val = pairs[::VAL_EVERY_TENTH]
        self.train = [p for i, p in enumerate(pairs) if i % VAL_EVERY_TENTH]

    @classmethod
    def from_folder(cls, folder: str, size):
        """Photos NAME.jpg|png with NAME.npy beside them (training/distill.py's output)."""
        images = [p for p in Path(folder).iterdir() if p.suffix.lower() in (".jpg", ".jpeg", ".png")]
        pairs = [(p, p.with_suffix(".npy")) for p in images if p.with_suffix(".npy").exists()]
        return cls(pairs, size, folder)

    @classmethod
    def from_labels(cls, folder: str, size, held_out: set):
        """An `ampi distill` label folder; photos in `held_out` (resolved paths) are left out."""
        images, labels = distill.read_label_folder(folder)
        pairs = [(images / photo, label) for photo, label in labels.items()
                 if (images / photo).resolve() not in held_out]
        return cls(pairs, size, folder)

    def _load(self, pair):
        from PIL import Image, ImageOps  # Debian's python3-pil
        image = ImageOps.exif_transpose(Image.open(pair[0])).convert("RGB")
        disparity = distill.read_disparity(pair[1])
        if disparity.shape != (image.height, image.width):
            raise ValueError(f"{pair[1]}: {disparity.shape[1]}x{disparity.shape[0]}, "
                             f"its photo {pair[0]} is {image.width}x{image.height}")
        image = np.asarray(image.resize((self.width, self.height), Image.BILINEAR))
        rgb, disparity = to_tensors(image, disparity)
        disparity = F.interpolate(disparity[None], size=(self.height, self.width), mode="bilinear",
                                  align_corners=False)[0]
        return rgb, disparity

    def sample(self, index: int, validation: bool):
        pairs = self.val if validation else self.train
        return self._load(pairs[index % len(pairs)])

    def validation_count(self, wanted: int) -> int:
        return min(wanted, len(self.val))


def make_source(spec: str, size, held_out: set = frozenset()):
    if spec == "scenes":
        return SceneSource(size)
    if spec == "cards":
        return CardSource(size)
    if spec.startswith("pairs:"):
        return PairFolderSource.from_folder(spec[len("pairs:"):], size)
    if spec.startswith("distilled:"):
        return PairFolderSource.from_labels(spec[len("distilled:"):], size, held_out)
    raise ValueError(f"unknown data source {spec!r} (scenes | cards | pairs:DIR | distilled:LABELS)")


def make_batch(source, first_index: int, batch: int, validation: bool, rng: random.Random):
    rgbs, disps = [], []
    for i in range(batch):
        rgb, disp = source.sample(first_index + i, validation)
        if not validation and rng.random() < 0.5:  # horizontal flip: a free, exact augmentation
            rgb, disp = rgb.flip(-1), disp.flip(-1)
        rgbs.append(rgb)
        disps.append(disp)
    return (torch.stack(rgbs).contiguous(memory_format=torch.channels_last),
            torch.stack(disps))


class TrainingBatches(torch.utils.data.Dataset):
    """Training group g (from the resumed step's group on): the synthetic batch of group g,
    drawn exactly as make_batch draws it, and for each of its steps (--scene-reuse
    consecutive steps share the batch) that step's real photos with their pairs. Indexed by
    group, so DataLoader workers make groups ahead and in parallel, and a resumed run draws
    the same batches. Reuse is for machines whose network outruns the scene renderer (a
    GPU): each rendered scene then teaches several steps, augmented after the first
    (scene_view)."""

    def __init__(self, source, args, size, first_step: int, ordinal_photos):
        self.source, self.args, self.size, self.first_step = source, args, size, first_step
        self.ordinal_photos = ordinal_photos
        self.first_group = first_step // args.scene_reuse

    def __len__(self):
        return max(0, -(-self.args.steps // self.args.scene_reuse) - self.first_group)

    def __getitem__(self, k):
        group, reuse = self.first_group + k, self.args.scene_reuse
        rng = random.Random(self.args.seed * 1_000_003 + group * reuse)
        rgb, disp = make_batch(self.source, group * self.args.batch, self.args.batch, False, rng)
        steps = range(max(group * reuse, self.first_step), min((group + 1) * reuse, self.args.steps))
        real = [self.real_photos(random.Random(f"real photos {self.args.seed} {step}")) for step in steps]
        return rgb, disp, list(steps), real

    def real_photos(self, rng: random.Random):
        """(photos [N, 3, h, w], N (points, signs) tuples, the teacher's labels [N, 1, h, w]
        or None)."""
        if not self.ordinal_photos:
            return None, [], None
        augment = self.args.photo_augment
        crop_share = ordinal_data.WIDE_CROP_SHARE if augment else ordinal_data.CROP_SHARE
        samples = [ordinal_data.training_sample(rng.choice(self.ordinal_photos), self.size, rng, crop_share)
                   for _ in range(self.args.ordinal_batch)]
        images = [jitter_colour(s[0], rng) if augment else s[0] for s in samples]
        real = torch.stack(images).contiguous(memory_format=torch.channels_last)
        teacher = torch.stack([s[3] for s in samples]) if samples[0][3] is not None else None
        return real, [(s[1], s[2]) for s in samples], teacher


def scene_view(rgb, disp, step: int, args):
    """The synthetic batch as step trains it: as drawn at the first step of its group, a
    new augmented view (augment_scene_batch) at each later one."""
    if step % args.scene_reuse == 0:
        return rgb, disp
    return augment_scene_batch(rgb, disp, random.Random(f"augment {args.seed} {step}"))


ZOOM = (1.0, 1.5)        # crop side = image side / zoom
COLOUR_GAIN = (0.85, 1.15)
GAMMA = (0.8, 1.25)


def augment_scene_batch(rgb: torch.Tensor, disp: torch.Tensor, rng: random.Random):
    """Another view of the same scenes for a reused batch: per image a random crop (1/1.5
    to all of each side) resized back, a horizontal flip half the time, a gain per colour
    channel and a gamma. Disparity is cropped, resized and flipped along; it needs no other
    change, since the loss normalises each target's range."""
    h, w = rgb.shape[-2:]
    rgbs, disps = [], []
    for image, target in zip(rgb, disp):
        zoom = rng.uniform(*ZOOM)
        ch, cw = round(h / zoom), round(w / zoom)
        y0, x0 = rng.randint(0, h - ch), rng.randint(0, w - cw)
        image = F.interpolate(image[None, :, y0:y0 + ch, x0:x0 + cw], size=(h, w), mode="bilinear",
                              align_corners=False)[0]
        target = F.interpolate(target[None, :, y0:y0 + ch, x0:x0 + cw], size=(h, w), mode="bilinear",
                               align_corners=False)[0]
        if rng.random() < 0.5:
            image, target = image.flip(-1), target.flip(-1)
        rgbs.append(jitter_colour(image, rng))
        disps.append(target)
    return torch.stack(rgbs).contiguous(memory_format=torch.channels_last), torch.stack(disps)


def jitter_colour(image: torch.Tensor, rng: random.Random) -> torch.Tensor:
    """image [3, h, w] in [0, 1] under a random gamma and a random gain per colour channel."""
    gain = torch.tensor([rng.uniform(*COLOUR_GAIN) for _ in range(3)], device=image.device).view(3, 1, 1)
    return (image.clamp(0, 1) ** rng.uniform(*GAMMA) * gain).clamp(0, 1)


def _worker_init(_):
    torch.set_num_threads(1)  # the network's threads are the main process's


def batches_ahead(dataset, workers: int):
    """A DataLoader over dataset's items, each a whole batch, made ahead by `workers`
    processes of one thread each (0: in the loop). Shared with train_inpaint.py."""
    ahead = {"num_workers": workers, "worker_init_fn": _worker_init, "prefetch_factor": 2} if workers else {}
    return torch.utils.data.DataLoader(dataset, batch_size=None, shuffle=False, **ahead)


# ---- metrics ------------------------------------------------------------------------------

METRIC_NAMES = ("delta1.25", "delta1.25^2", "delta1.25^3", "rmse", "rel")


def aligned_metrics(pred: torch.Tensor, target: torch.Tensor) -> dict:
    """The paper's depth metrics after median and standard-deviation alignment, averaged
    over the batch. The target disparity is normalised per image as in the loss (min-max
    to [0, 10]) and shifted by 1 so that it is strictly positive; the prediction is
    aligned to it (same median, same standard deviation) and clamped to 1e-3. delta < t:
    share of pixels with max(p / y, y / p) < t; RMSE and REL = mean |p - y| / y are in
    the units of the normalised target [1, 11]."""
    rows = []
    for p, t in zip(pred.flatten(1), losses.normalise_target(target).flatten(1) + 1.0):
        p = (p - p.median()) / p.std().clamp_min(1e-6) * t.std() + t.median()
        p = p.clamp_min(1e-3)
        ratio = torch.maximum(p / t, t / p)
        rows.append([float((ratio < 1.25 ** k).float().mean()) for k in (1, 2, 3)]
                    + [float(((p - t) ** 2).mean().sqrt()), float(((p - t).abs() / t).mean())])
    return dict(zip(METRIC_NAMES, np.mean(rows, axis=0).tolist()))


@torch.no_grad()
def validate(model, batches, device="cpu", invariant=False):
    """(mean loss, mean metrics) over the fixed validation batches."""
    model.eval()
    total, metrics = 0.0, []
    for rgb, disp in batches:
        rgb, disp = rgb.to(device), disp.to(device)
        outputs = model(rgb)
        loss, _ = losses.depth_loss(outputs, disp, invariant)
        total += float(loss)
        metrics.append(list(aligned_metrics(outputs[-1], disp).values()))
    model.train()
    return total / len(batches), dict(zip(METRIC_NAMES, np.mean(metrics, axis=0).tolist()))


@torch.no_grad()
def validate_ordinal(model, photos, long_side: int, device="cpu"):
    """WHDR of the network on the ordinal validation photos, each run as the engine runs
    it: long side long_side, aspect kept (ordinal_data.validation_sample, engine_disparity)."""
    model.eval()
    wrong, pairs = 0.0, 0
    for photo in photos:
        rgb, points, signs = ordinal_data.validation_sample(photo, long_side)
        disparity = ordinal_data.engine_disparity(model, rgb, device)
        photo_wrong, photo_pairs = ordinal_data.whdr_counts(disparity.cpu(), points, signs)
        wrong, pairs = wrong + photo_wrong, pairs + photo_pairs
    model.train()
    return wrong / max(pairs, 1)


# ---- checkpoints --------------------------------------------------------------------------

def save_checkpoint(path: Path, state: dict):
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    os.replace(tmp, path)  # a crash mid-write never leaves a torn checkpoint


def log_line(run: Path, text: str):
    line = time.strftime("%Y-%m-%d %H:%M:%S ") + text
    print(line, flush=True)
    with open(run / "train.log", "a") as f:
        f.write(line + "\n")


def parse_size(text: str):
    w, h = (int(v) for v in text.lower().split("x"))
    return w, h


def initial_model(args, source, size, resuming: bool):
    """The network to start from: new, or --init's weights (a checkpoint, or an exported
    .ampw with its BatchNorms unfolded again), unless a checkpoint is about to be resumed."""
    if not args.init or resuming:
        return depth_model.build(args.model)
    if not args.init.endswith(".ampw"):
        model = depth_model.build(args.model)
        model.load_state_dict(torch.load(args.init, map_location="cpu", weights_only=False)["model"])
        return model
    import export_depth
    model = export_depth.import_ampw(args.init)
    if model.arch["name"] != args.model:
        raise SystemExit(f"--init {args.init}: holds a {model.arch['name']} network, not {args.model}")
    rng = random.Random(args.seed)
    batches = [make_batch(source, VAL_SEED_START // 2 + i * 8, 8, False, rng)[0] for i in range(8)]
    return export_depth.unfold_batchnorm(model, batches).train()


LR_FLOOR = 0.01  # the cosine decay ends at this share of --lr


def cosine_lr(args, step: int) -> float:
    """The learning rate of step (counted from the run's start) under --lr-decay cosine:
    --lr at step 0, LR_FLOOR x --lr from --decay-steps on, half a cosine between. A function
    of the step alone, so a resumed run continues the same curve whatever learning rate its
    checkpoint holds (a slim one's is that of its last step)."""
    floor = args.lr * LR_FLOOR
    done = min(step, args.decay_steps) / args.decay_steps
    return floor + (args.lr - floor) * 0.5 * (1.0 + math.cos(math.pi * done))


def follow_schedule(optimiser, args, step: int):
    """Under --lr-decay cosine, the learning rate step trains at; otherwise nothing (the
    plateau rule moves it at validations)."""
    if args.lr_decay == "cosine":
        for group in optimiser.param_groups:
            group["lr"] = cosine_lr(args, step)


def forward(model, rgb, args):
    """The training forward pass; with --bf16 its convolutions run in bfloat16 (the heads,
    and so every loss, stay in fp32: depth_model.DepthNet.head). Weights, their gradients
    and Adam's state stay fp32, so no loss scaling is needed: bf16 has fp32's range."""
    with torch.autocast(torch.device(args.device).type, dtype=torch.bfloat16, enabled=args.bf16):
        return model(rgb)


def training_step(model, optimiser, batch, args):
    """One Adam step on a batch of TrainingBatches: (loss, its parts, ranking loss, loss on
    the teacher's labels)."""
    rgb, disp, real_rgb, pairs, real_teacher = batch
    rgb, disp = rgb.to(args.device, non_blocking=True), disp.to(args.device, non_blocking=True)
    rank = taught = torch.zeros(())
    invariant = args.loss == "invariant"
    if real_rgb is None:
        loss, parts = losses.depth_loss(forward(model, rgb, args), disp, invariant)
    else:  # one pass over both: the BatchNorms see real photos too
        real_rgb = real_rgb.to(args.device, non_blocking=True)
        pairs = [(points.to(args.device), signs.to(args.device)) for points, signs in pairs]
        outputs = forward(model, torch.cat([rgb, real_rgb]).contiguous(memory_format=torch.channels_last), args)
        loss, parts = losses.depth_loss([o[:len(rgb)] for o in outputs], disp, invariant)
        # the paper's loss holds the output's scale; without it the ranking loss, which
        # falls as the scale grows, reads the output normalised too
        real_disparity = outputs[-1][len(rgb):]
        rank = ordinal_data.ranking_loss(losses.normalise_median_mad(real_disparity) if invariant else real_disparity,
                                         pairs)
        loss = loss + args.rank_weight * rank
        if real_teacher is not None:  # the paper's loss on the real photos' pseudo ground truth
            taught, _ = losses.depth_loss([o[len(rgb):] for o in outputs], real_teacher.to(args.device), invariant)
            loss = loss + args.teacher_weight * taught
    optimiser.zero_grad(set_to_none=True)
    loss.backward()
    optimiser.step()
    return loss, parts, rank, taught


class WeightAverage:
    """An exponential moving average of the weights and BatchNorm statistics (--ema):
    what validation measures and best.pt keeps when on. At a learning rate where the
    ordinal validation swings by several points from one validation to the next, the
    average of the recent steps is steadier than any one of them."""

    def __init__(self, model, decay: float):
        import copy
        self.decay = decay
        self.model = copy.deepcopy(model).eval()
        for p in self.model.parameters():
            p.requires_grad_(False)

    @torch.no_grad()
    def update(self, model):
        for mine, theirs in zip(self.model.state_dict().values(), model.state_dict().values()):
            if mine.dtype.is_floating_point:
                mine.mul_(self.decay).add_(theirs, alpha=1.0 - self.decay)
            else:
                mine.copy_(theirs)


def resume(ckpt_path: Path, model, average, optimiser, scheduler, args, best_of: str):
    """(step, best score) of the checkpoint, its state loaded into model, the weight
    average (or None), optimiser and scheduler. A slim checkpoint (training/gpu_run.py)
    has no Adam moments: they start again at its learning rate. A best score of another
    measure than best_of is dropped."""
    ckpt = torch.load(ckpt_path, map_location=args.device, weights_only=False)
    if ckpt["model_name"] != args.model:
        raise SystemExit(f"{ckpt_path}: holds a {ckpt['model_name']} model, not {args.model}")
    model.load_state_dict(ckpt["model"])
    if average is not None:  # a checkpoint without one starts the average at its weights
        average.model.load_state_dict(ckpt.get("ema", ckpt["model"]))
    scheduler.load_state_dict(ckpt["scheduler"])
    if "optimiser" in ckpt:
        optimiser.load_state_dict(ckpt["optimiser"])
    else:
        for group in optimiser.param_groups:
            group["lr"] = ckpt["lr"]
    best = ckpt["best_val"] if ckpt.get("best_of", "val_loss") == best_of else math.inf
    return ckpt["step"], best, "" if "optimiser" in ckpt else " (slim: Adam restarts)"


def train(args):
    if not args.malloc_defaults:
        malloc_reuse.keep_freed_blocks()
    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    run = Path(args.run)
    run.mkdir(parents=True, exist_ok=True)
    size = parse_size(args.size)
    import photo_folder  # the photo folder
    held_out = set()
    if args.data.startswith("distilled:"):
        held_out = ordinal_data.validation_photos(photo_folder.photo_root(), args.ordinal or ordinal_data.ORDINAL_FILE)
    source = make_source(args.data, size, held_out)
    ordinal_train = ordinal_val = None
    if args.ordinal:
        ordinal_train = ordinal_data.load_split("train", photo_folder.photo_root(), args.ordinal,
                                                args.teacher_labels)
        ordinal_val = ordinal_data.load_split("val", photo_folder.photo_root(), args.ordinal)
    best_of = "ordinal_whdr" if ordinal_val else "val_loss"  # what best.pt keeps the lowest of
    ckpt_path = run / "checkpoint.pt"
    model = initial_model(args, source, size, resuming=ckpt_path.exists())
    if size[0] % model.multiple or size[1] % model.multiple:
        raise SystemExit(f"--size {args.size}: both sides must be multiples of {model.multiple}")
    model = model.to(args.device, memory_format=torch.channels_last)
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr)
    scheduler = torch.optim.lr_scheduler.ReduceLROnPlateau(
        optimiser, factor=0.2, patience=args.patience)
    step, best = 0, math.inf
    average = WeightAverage(model, args.ema) if args.ema else None
    measured = average.model if average else model  # what validation measures and best.pt keeps
    if ckpt_path.exists():
        step, best, note = resume(ckpt_path, model, average, optimiser, scheduler, args, best_of)
        log_line(run, f"resumed {args.model} at step {step} from {ckpt_path}{note}")
    elif args.init:
        log_line(run, f"initialised {args.model} from {args.init}")
    follow_schedule(optimiser, args, step)
    val_count = source.validation_count(args.val_count)
    teacher_note = (f", teacher's labels {args.teacher_labels} weight {args.teacher_weight:g}"
                    if args.teacher_labels else "")
    real = (f" + {args.ordinal_batch} real photos ({len(ordinal_train)} with pairs, rank weight {args.rank_weight:g}"
            f"{teacher_note}{', wide crops and colour jitter' if args.photo_augment else ''})"
            if ordinal_train else "")
    ema = f", weights averaged (decay {args.ema:g})" if average else ""
    decay = (f" (cosine decay from {args.lr:.2e} to {args.lr * LR_FLOOR:.2e} at step {args.decay_steps})"
             if args.lr_decay == "cosine" else "")
    loss_note = ", scale- and shift-invariant loss" if args.loss == "invariant" else ""
    log_line(run, f"train {args.model} ({depth_model.parameter_count(model)} parameters) on {args.data}{real}{loss_note} "
                  f"at {size[0]}x{size[1]}, batch {args.batch}, lr {optimiser.param_groups[0]['lr']:.2e}{decay}{ema}, "
                  f"{args.threads} threads, {args.workers} workers{', bf16 autocast' if args.bf16 else ''}")

    def checkpoint():
        save_checkpoint(ckpt_path, {
            "model_name": args.model, "model": model.state_dict(), "optimiser": optimiser.state_dict(),
            "scheduler": scheduler.state_dict(), "step": step, "best_val": best, "best_of": best_of,
            **({"ema": average.model.state_dict()} if average else {})})

    val_batches = [make_batch(source, first, min(args.batch, val_count - first), True, random.Random(0))
                   for first in range(0, val_count, args.batch)]  # rendered once, not every validation

    def validation():
        nonlocal best
        val_loss, metrics = validate(measured, val_batches, args.device, args.loss == "invariant")
        if args.lr_decay == "none":
            scheduler.step(val_loss)
        whdr = validate_ordinal(measured, ordinal_val, max(size), args.device) if ordinal_val else None
        score = whdr if whdr is not None else val_loss
        if score < best:  # the weights worth exporting, kept apart from the latest
            best = score
            save_checkpoint(run / "best.pt", {"model_name": args.model, "model": measured.state_dict(),
                                              "step": step, "val_loss": val_loss, "metrics": metrics,
                                              "ordinal_whdr": whdr})
        shown = " ".join(f"{name} {value:.4f}" for name, value in metrics.items())
        if whdr is not None:
            shown += f" ordinal_whdr {whdr:.4f}"
        log_line(run, f"val step {step} loss {val_loss:.4f} {shown} best {best:.4f}")

    batches = batches_ahead(TrainingBatches(source, args, size, step, ordinal_train), args.workers)
    t0, seen, timed_from = time.time(), 0, None
    for rgb, disp, steps, real in batches:
        rgb = rgb.to(args.device, non_blocking=True)
        disp = disp.to(args.device, non_blocking=True)
        for step_of_batch, (real_rgb, pairs, real_teacher) in zip(steps, real):
            follow_schedule(optimiser, args, step)
            loss, parts, rank, taught = training_step(
                model, optimiser, (*scene_view(rgb, disp, step_of_batch, args), real_rgb, pairs, real_teacher), args)
            if average:
                average.update(model)
            step += 1
            seen += 1
            trained_until = time.time()
            if seen == 1:
                timed_from = trained_until  # the rate leaves out start-up and the first step
            if step % args.log_every == 0:
                log_line(run, f"step {step} loss {float(loss):.4f} data {parts['data']:.4f} grad {parts['grad']:.4f} "
                              f"rank {float(rank):.4f}{f' teacher {float(taught):.4f}' if args.teacher_labels else ''} lr {optimiser.param_groups[0]['lr']:.2e} "
                              f"{(time.time() - t0) / seen:.2f} s/step")
            out_of_time = args.minutes > 0 and time.time() - t0 >= 60 * args.minutes
            if step % args.val_every == 0 or step == args.steps or out_of_time:
                validation()
            if step % args.checkpoint_every == 0 or step == args.steps or out_of_time:
                checkpoint()
            if out_of_time:
                break
        if out_of_time:
            log_line(run, f"stopped after {args.minutes:g} minutes at step {step}")
            break
    else:
        log_line(run, f"done at step {step}")
    samples = args.batch + (args.ordinal_batch if ordinal_train else 0)
    return {"steps": seen - 1, "seconds": trained_until - timed_from if seen else 0.0,
            "samples_per_step": samples}


def parse_args(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--model", choices=sorted(depth_model.ARCHITECTURES), default="lite")
    p.add_argument("--run", required=True, help="run folder: checkpoint.pt and train.log")
    p.add_argument("--data", default="scenes", help="scenes | cards | pairs:DIR | distilled:LABELS")
    p.add_argument("--size", default="256x192", help="WIDTHxHEIGHT, multiples of 32")
    p.add_argument("--batch", type=int, default=4)
    p.add_argument("--steps", type=int, default=20000, help="total steps (a resumed run continues to this)")
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--patience", type=int, default=5,
                   help="validations without improvement before lr x0.2 (with --lr-decay none)")
    p.add_argument("--lr-decay", choices=("none", "cosine"), default="none",
                   help="none: x0.2 on a plateau; cosine: --lr to --lr / 100 at --decay-steps, by the step")
    p.add_argument("--decay-steps", type=int, default=0,
                   help="the step (counted from the run's start) where --lr-decay cosine reaches its floor")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--log-every", type=int, default=10)
    p.add_argument("--val-every", type=int, default=200)
    p.add_argument("--val-count", type=int, default=32)
    p.add_argument("--checkpoint-every", type=int, default=50)
    p.add_argument("--init", help="start from this checkpoint's weights (fine-tuning)")
    p.add_argument("--device", default="cpu", help="cpu, or cuda on a GPU machine")
    p.add_argument("--minutes", type=float, default=0,
                   help="stop after this many minutes, validated and checkpointed (0: run to --steps)")
    p.add_argument("--scene-reuse", type=int, default=1,
                   help="steps each rendered scene batch trains, augmented after the first (a GPU's setting)")
    p.add_argument("--workers", type=int, default=1, help="processes making batches ahead (0: in the loop)")
    p.add_argument("--ordinal", help="ordinal set (training/ordinal/ordinal.json.gz): ranking loss on its "
                                     "training photos, WHDR on its validation photos")
    p.add_argument("--ordinal-batch", type=int, default=4, help="real photos per step with --ordinal")
    p.add_argument("--rank-weight", type=float, default=1.0, help="weight of the ranking loss")
    p.add_argument("--photo-augment", action="store_true",
                   help="the real photos' crops keep 50-100%% of each side (70-100%% without) and take the "
                        "scenes' colour jitter: more distinct views of the few training photos")
    p.add_argument("--loss", choices=("paper", "invariant"), default="paper",
                   help="paper: the target min-max normalised to [0, 10]; invariant: target and output "
                        "normalised by median and mean absolute deviation (losses.py)")
    p.add_argument("--teacher-labels", help="an `ampi distill` label folder of the photo folder: the paper's "
                                            "loss on the --ordinal training photos' labels too (self-distillation)")
    p.add_argument("--teacher-weight", type=float, default=1.0, help="weight of the loss on --teacher-labels")
    p.add_argument("--ema", type=float, default=0.0,
                   help="validate and keep an exponential moving average of the weights with this decay "
                        "(e.g. 0.999; 0: the weights as trained)")
    p.add_argument("--bf16", action="store_true",
                   help="bfloat16 autocast for the training forward pass (CPUs with AVX512-BF16 or AMX, "
                        "GPUs): faster, weights and losses in fp32 (training/BENCH_TRAIN.md); validation stays fp32")
    p.add_argument("--malloc-defaults", action="store_true",
                   help="leave glibc's malloc thresholds as they are (training/malloc_reuse.py: for a comparison)")
    args = p.parse_args(argv)
    if args.teacher_labels and not args.ordinal:
        raise SystemExit("train_depth.py: --teacher-labels labels the --ordinal training photos; give --ordinal")
    if args.lr_decay == "cosine" and args.decay_steps <= 0:
        raise SystemExit("train_depth.py: --lr-decay cosine needs --decay-steps N (N > 0)")
    return args


def main(argv=None):
    return train(parse_args(argv))


if __name__ == "__main__":
    main()

"""Trains the inpainting generator (training/inpaint_model.py) on margins removed from
sliced photos (training/inpaint_data.py), with the paper's loss

    L_G = L_data + 0.1 L_grad + 0.01 L_disc + 0.01 L_perc

  L_data  mean |y^ - y| over the removed pixels (RGB in [-1, 1])
  L_grad  sum over scales s = 0..3 of mean |grad_x d_s| + |grad_y d_s|, d = (y^ - y) on
          the removed pixels, 0 elsewhere, d_s its 2^s average pooling (the depth loss of
          training/losses.py applied to RGB), divided by the removed fraction so it is a
          mean over the removed pixels like L_data
  L_disc  the generator's hinge term -mean D(composite) against the patch discriminator
  L_perc  mean |phi(composite) - phi(original)| over the first two encoder stages of
          our depth network, frozen: no pretrained VGG exists here (DESIGN.md), so the
          features of our own trained network stand in for it. Until a depth checkpoint is
          given (--perceptual), the encoder keeps its seeded random initialisation:
          random convolutional features still measure local structure, and the choice is
          recorded in the checkpoint and the log.

The discriminator minimises the hinge loss mean relu(1 - D(real)) + mean relu(1 + D(fake)).
Adam with lr 2e-4 (G) and 1e-4 (D) as in the paper; betas (0.5, 0.999), the usual choice
for GAN training (the paper does not give them).

Resumable: RUN_DIR/last.pt holds both networks, both optimisers and the step, written
atomically every --checkpoint-every steps and at the end; each step's batch is drawn from
(--seed, step), so a resumed run draws what an uninterrupted one would have. RUN_DIR/best.pt
holds the generator with the best validation PSNR, RUN_DIR/log.csv one row per logged step,
RUN_DIR/train.log every line the run prints.

    nice -n 10 /usr/bin/python3 training/train_inpaint.py --run-dir training/runs/inpaint

On a GPU machine (--device cuda), --workers processes make the batches ahead (slicing crops
and their prefill is the work; the networks are small), and --minutes stops the run
validated and checkpointed; training/gpu_run.py packs and launches such runs.
"""
from __future__ import annotations

import argparse
import csv
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import depth_model  # noqa: E402
import inpaint_data as data  # noqa: E402
from inpaint_model import PREFILL, InpaintGenerator, PatchDiscriminator  # noqa: E402
from losses import gradient_loss  # noqa: E402
import malloc_reuse  # noqa: E402
from export_inpaint import import_ampw as import_generator  # noqa: E402
from train_depth import batches_ahead, log_line, save_checkpoint  # noqa: E402

W_GRAD, W_DISC, W_PERC = 0.1, 0.01, 0.01
LR_G, LR_D, BETAS = 2e-4, 1e-4, (0.5, 0.999)
PERCEPTUAL_STAGES = 2  # 1/2 and 1/4 resolution: the third stage would double the step time
PERCEPTUAL_SEED = 1234
VALIDATION_SAMPLES, VALIDATION_SEED = 96, 0


class PerceptualFeatures(torch.nn.Module):
    """The first encoder stages of our depth network, frozen (eval mode, no gradients to
    its weights; gradients do flow to its input)."""

    def __init__(self, checkpoint: str | None):
        super().__init__()
        torch.manual_seed(PERCEPTUAL_SEED)
        net = depth_model.build("lite")
        self.source = "random-init(seed=%d)" % PERCEPTUAL_SEED
        if checkpoint and checkpoint.endswith(".ampw"):
            # Folded weights: in eval mode the imported network computes exactly the
            # trained one, and these features only ever run in eval mode.
            import export_depth
            net = export_depth.import_ampw(checkpoint)
            self.source = os.path.abspath(checkpoint)
        elif checkpoint:
            state = torch.load(checkpoint, map_location="cpu", weights_only=False)
            net.load_state_dict(state.get("model", state))
            self.source = os.path.abspath(checkpoint)
        self.register_buffer("mean", net.mean.clone())
        self.register_buffer("std", net.std.clone())
        self.stages = torch.nn.ModuleList(net.enc[:PERCEPTUAL_STAGES])
        self.eval()
        for p in self.parameters():
            p.requires_grad_(False)

    def train(self, mode: bool = True):
        return super().train(False)  # BatchNorm stays on its running statistics

    def forward(self, rgb_pm1: torch.Tensor):
        x = ((rgb_pm1 + 1) * 0.5 - self.mean) / self.std
        feats = []
        for stage in self.stages:
            x = stage(depth_model.haar_dwt(x))
            feats.append(x)
        return feats


def masked_mean(x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean of x over the pixels where mask is 1 (x has C channels, mask one)."""
    return (x * mask).sum() / (mask.sum() * x.shape[1]).clamp_min(1.0)


def pixel_losses(pred, target, removed):
    diff = (pred - target) * removed
    data_term = masked_mean(diff.abs(), removed)
    grad_term = gradient_loss(diff) / removed.mean().clamp_min(1e-3)
    return data_term, grad_term


def generator_step(g, d, phi, opt_g, rgb, hole, removed, prefilled):
    pred = g(prefilled, hole)
    fake = rgb * (1 - removed) + pred * removed
    l_data, l_grad = pixel_losses(pred, rgb, removed)
    l_disc = -d(fake, removed).mean()
    with torch.no_grad():
        real_features = phi(rgb)
    l_perc = sum((a - b).abs().mean() for a, b in zip(phi(fake), real_features)) / PERCEPTUAL_STAGES
    loss = l_data + W_GRAD * l_grad + W_DISC * l_disc + W_PERC * l_perc
    opt_g.zero_grad(set_to_none=True)
    loss.backward()
    opt_g.step()
    parts = {"loss_g": loss, "data": l_data, "grad": l_grad, "disc": l_disc, "perc": l_perc}
    return fake.detach(), {k: float(v) for k, v in parts.items()}


def discriminator_step(d, opt_d, rgb, fake, removed):
    loss = F.relu(1 - d(rgb, removed)).mean() + F.relu(1 + d(fake, removed)).mean()
    opt_d.zero_grad(set_to_none=True)
    loss.backward()
    opt_d.step()
    return float(loss)


def psnr(mse: float) -> float:
    """For RGB in [-1, 1], peak-to-peak 2."""
    return 10 * math.log10(4.0 / max(mse, 1e-12))


@torch.no_grad()
def validate(g, val_batches):
    """Mean L1 and PSNR over the removed pixels of the fixed validation samples."""
    g.eval()
    l1, se, count = 0.0, 0.0, 0.0
    for rgb, hole, removed, prefilled in val_batches:
        diff = (g(prefilled, hole) - rgb) * removed
        l1 += float(diff.abs().sum())
        se += float((diff ** 2).sum())
        count += float(removed.sum()) * 3
    g.train()
    return l1 / count, psnr(se / count)


def fixed_validation(source: data.SampleSource, batch: int):
    rng = np.random.default_rng(VALIDATION_SEED)
    return [source.batch(rng, batch) for _ in range(VALIDATION_SAMPLES // batch)]


def validation_key(args):
    """What the fixed validation samples depend on besides the photos."""
    return {"crop": args.crop, "batch": args.batch, "seed": VALIDATION_SEED, "prefill": PREFILL,
            "standin_too": args.standin_too}


class TrainingBatches(torch.utils.data.Dataset):
    """The batch of every step from first_step to --steps, drawn with a generator seeded by
    (--seed, step): DataLoader workers make them ahead and in parallel (--workers), and a
    resumed run draws the batches an uninterrupted one would have."""

    def __init__(self, source: data.SampleSource, args, first_step: int):
        self.source, self.args, self.first_step = source, args, first_step

    def __len__(self):
        return max(0, self.args.steps - self.first_step)

    def __getitem__(self, k):
        return self.source.batch(np.random.default_rng([self.args.seed, self.first_step + k]), self.args.batch)


def load_or_init(args, g, d, opt_g, opt_d, log):
    """(step, best validation PSNR) of RUN_DIR/last.pt, its state loaded into the networks
    and optimisers; (0, -inf) for a new run. A slim checkpoint (training/gpu_run.py) has no
    Adam moments: they start again."""
    path = os.path.join(args.run_dir, "last.pt")
    if not os.path.exists(path):
        return 0, -math.inf
    ck = torch.load(path, map_location="cpu", weights_only=False)  # our own file, from any torch
    g.load_state_dict(ck["generator"])
    d.load_state_dict(ck["discriminator"])
    if "opt_g" in ck:
        opt_g.load_state_dict(ck["opt_g"])
        opt_d.load_state_dict(ck["opt_d"])
    for opt, lr in ((opt_g, args.lr_g), (opt_d, args.lr_d)):  # the command line wins
        for group in opt.param_groups:
            group["lr"] = lr
    torch.set_rng_state(ck["torch_rng"])
    log(f"resumed from {path} at step {ck['step']}" + ("" if "opt_g" in ck else " (slim: Adam restarts)"))
    best = ck["best_psnr"]
    if ck.get("validation") != validation_key(args):
        log("the validation samples changed (crop or batch): the best PSNR starts over")
        best = -math.inf
    return ck["step"], best


def checkpoint(args, step, best, g, d, opt_g, opt_d, phi):
    save_checkpoint(Path(args.run_dir) / "last.pt", {
        "step": step, "best_psnr": best, "generator": g.state_dict(), "residual": g.residual, "prefill": PREFILL,
        "discriminator": d.state_dict(), "opt_g": opt_g.state_dict(), "opt_d": opt_d.state_dict(),
        "torch_rng": torch.get_rng_state(), "perceptual": phi.source, "validation": validation_key(args)})


def save_best(args, step, psnr_db, g):
    save_checkpoint(Path(args.run_dir) / "best.pt", {"step": step, "val_psnr": psnr_db, "generator": g.state_dict(),
                                                     "residual": g.residual, "prefill": PREFILL})


def parse_args(argv):
    ap = argparse.ArgumentParser(description="train the MPI inpainting generator")
    ap.add_argument("--photos", default=data.DEFAULT_PHOTOS)
    ap.add_argument("--disparity-dir", default=data.DEFAULT_DISPARITY_DIR)
    ap.add_argument("--planes-dir", default=None,
                    help="plane maps sliced ahead (inpaint_data.write_planes; what gpu_run.py carries): "
                         "they replace the disparity of the photos they cover")
    ap.add_argument("--run-dir", default=os.path.join(os.path.dirname(__file__), "runs", "inpaint"))
    ap.add_argument("--perceptual", default=None,
                    help="depth network for L_perc: a train_depth.py checkpoint or an exported .ampw")
    ap.add_argument("--init", default=None,
                    help="a new run's generator starts from this exported .ampw (the bundled weights)")
    ap.add_argument("--lr-g", type=float, default=LR_G, help="generator learning rate (paper: 2e-4)")
    ap.add_argument("--lr-d", type=float, default=LR_D, help="discriminator learning rate (paper: 1e-4)")
    ap.add_argument("--steps", type=int, default=1_000_000, help="stop after this many steps")
    ap.add_argument("--minutes", type=float, default=0,
                    help="stop after this many minutes of training, validated and checkpointed (0: run to --steps)")
    ap.add_argument("--batch", type=int, default=6)
    ap.add_argument("--crop", type=int, default=128)
    ap.add_argument("--device", default="cpu", help="cpu, or cuda on a GPU machine")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--workers", type=int, default=0, help="processes making batches ahead (0: in the loop)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--log-every", type=int, default=25)
    ap.add_argument("--validate-every", type=int, default=250)
    ap.add_argument("--checkpoint-every", type=int, default=100)
    ap.add_argument("--max-photos", type=int, default=0, help="use only the first N (smoke tests)")
    ap.add_argument("--standin-too", action="store_true",
                    help="slice photos with a cached disparity map a second time with the stand-in")
    ap.add_argument("--plain", action="store_true",
                    help="version-1 generator: hole zeroed, no push-pull pre-fill, no residual")
    return ap.parse_args(argv)


def networks(args, log):
    """The generator (new, or --init's for a new run), the discriminator and the perceptual
    features, on --device."""
    torch.manual_seed(args.seed)
    g, d = InpaintGenerator(residual=not args.plain), PatchDiscriminator()
    if args.init and not os.path.exists(os.path.join(args.run_dir, "last.pt")):
        g = import_generator(args.init)
        if g.residual == args.plain:
            raise SystemExit(f"{args.init}: its generator version does not match --plain")
        log(f"generator starts from {args.init}")
    phi = PerceptualFeatures(args.perceptual)
    log(f"perceptual features: depth encoder, {phi.source}")
    return g.to(args.device), d.to(args.device), phi.to(args.device)


def main(argv=None):
    args = parse_args(argv)
    malloc_reuse.keep_freed_blocks()
    torch.set_num_threads(args.threads)
    os.makedirs(args.run_dir, exist_ok=True)

    def log(msg):
        log_line(Path(args.run_dir), msg)

    train_rel, val_rel = data.split_photos(data.list_photos(args.photos))
    if args.max_photos:
        train_rel, val_rel = train_rel[:args.max_photos], val_rel[:max(1, args.max_photos // 10)]
    prepare = lambda rels: data.prepare_photos(  # noqa: E731
        args.photos, rels, args.disparity_dir, log, standin_too=args.standin_too, planes_dir=args.planes_dir)
    train = data.SampleSource(prepare(train_rel), args.crop)
    val_batches = [[t.to(args.device) for t in batch]
                   for batch in fixed_validation(data.SampleSource(prepare(val_rel), args.crop), args.batch)]

    g, d, phi = networks(args, log)
    opt_g = torch.optim.Adam(g.parameters(), lr=args.lr_g, betas=BETAS)
    opt_d = torch.optim.Adam(d.parameters(), lr=args.lr_d, betas=BETAS)
    step, best = load_or_init(args, g, d, opt_g, opt_d, log)
    if step == 0:  # what training starts from (the prefill itself for an untrained residual net)
        best = validate(g, val_batches)[1]
        save_best(args, 0, best, g)
        log(f"step 0: validation PSNR {best:.4f} (best.pt keeps it until a step beats it)")
    log(f"train on {args.device}: batch {args.batch} of {args.crop} px crops, {args.workers} workers")

    log_path = os.path.join(args.run_dir, "log.csv")
    fields = ["step", "time", "loss_g", "data", "grad", "disc", "perc", "loss_d", "val_l1", "val_psnr"]
    new_log = not os.path.exists(log_path)
    with open(log_path, "a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields)
        if new_log:
            writer.writeheader()
        running, summed, started = {}, 0, time.time()
        for batch in batches_ahead(TrainingBatches(train, args, step), args.workers):
            rgb, hole, removed, prefilled = (t.to(args.device, non_blocking=True) for t in batch)
            fake, parts = generator_step(g, d, phi, opt_g, rgb, hole, removed, prefilled)
            parts["loss_d"] = discriminator_step(d, opt_d, rgb, fake, removed)
            step += 1
            for k, v in parts.items():
                running[k] = running.get(k, 0.0) + v
            summed += 1  # fewer than --log-every after a resume
            out_of_time = args.minutes > 0 and time.time() - started >= 60 * args.minutes
            row = None
            if step % args.log_every == 0:
                row = {k: running[k] / summed for k in running}
                running, summed = {}, 0
            if step % args.validate_every == 0 or step == args.steps or out_of_time:
                row = row or {}
                row["val_l1"], row["val_psnr"] = validate(g, val_batches)
                if row["val_psnr"] > best:
                    best = row["val_psnr"]
                    save_best(args, step, best, g)
            if row is not None:
                row.update(step=step, time=round(time.time() - started, 1))
                writer.writerow({k: (f"{v:.5f}" if isinstance(v, float) else v) for k, v in row.items()})
                f.flush()
                log(" ".join(f"{k}={v:.4f}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()))
            if step % args.checkpoint_every == 0:
                checkpoint(args, step, best, g, d, opt_g, opt_d, phi)
            if out_of_time:
                log(f"stopped after {args.minutes:g} minutes at step {step}")
                break
    checkpoint(args, step, best, g, d, opt_g, opt_d, phi)
    return 0


if __name__ == "__main__":
    sys.exit(main())

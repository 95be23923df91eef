"""How far one training step's gradient under train_depth.py --bf16 is from fp32's, on a
run's own checkpoint and the batches that run trains on: the measurement behind taking
--bf16 into a run (training/DEPTH.md).

    AMPI_PHOTO_ROOT=training/data_cache/photos /usr/bin/python3 training/bf16_agreement.py \\
        training/runs/heavy-long/checkpoint.pt --batches 4 -- TRAIN_DEPTH_ARGUMENTS...

The arguments after `--` are the run's own (model, data, --ordinal, --teacher-labels, ...).
Each batch is one the run would train on after the checkpoint's step; both precisions
start from the same weights and BatchNorm statistics. One line per batch: the two losses,
the cosine between the two gradients and the ratio of their norms.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import depth_model  # noqa: E402
import malloc_reuse  # noqa: E402
import ordinal_data  # noqa: E402
import photo_folder  # noqa: E402
import train_depth  # noqa: E402


def step_gradient(model, batch, args, bf16: bool):
    """(loss, the gradient of every parameter as one vector) of one training step on
    batch, with the weights left where they are."""
    class NoStep:
        def zero_grad(self, set_to_none=True):
            model.zero_grad(set_to_none=set_to_none)

        def step(self):
            pass

    loss, *_ = train_depth.training_step(model, NoStep(), batch, argparse.Namespace(**{**vars(args), "bf16": bf16}))
    return float(loss), torch.cat([p.grad.flatten() for p in model.parameters()])


def agreement(model, batch, args) -> dict:
    start = {k: v.clone() for k, v in model.state_dict().items()}
    exact_loss, exact = step_gradient(model, batch, args, bf16=False)
    model.load_state_dict(start)  # the same BatchNorm statistics for both
    fast_loss, fast = step_gradient(model, batch, args, bf16=True)
    model.load_state_dict(start)
    return {"loss fp32": exact_loss, "loss bf16": fast_loss,
            "cosine": float(torch.dot(exact, fast) / exact.norm() / fast.norm()),
            "norm ratio": float(fast.norm() / exact.norm())}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("checkpoint", help="a train_depth.py checkpoint.pt")
    p.add_argument("--batches", type=int, default=4)
    argv = sys.argv[1:] if argv is None else argv
    split = argv.index("--") if "--" in argv else len(argv)   # after it: the run's own arguments
    args = p.parse_args(argv[:split])
    if not Path(args.checkpoint).is_file():
        raise SystemExit(f"bf16_agreement.py: {args.checkpoint}: no such file")
    run_args = train_depth.parse_args(["--run", "unused", *argv[split + 1:]])
    malloc_reuse.keep_freed_blocks()
    torch.set_num_threads(run_args.threads)
    ckpt = torch.load(args.checkpoint, map_location="cpu")
    model = depth_model.build(run_args.model)
    model.load_state_dict(ckpt["model"])
    model = model.to(memory_format=torch.channels_last).train()
    size = train_depth.parse_size(run_args.size)
    photos = (ordinal_data.load_split("train", photo_folder.photo_root(), run_args.ordinal, run_args.teacher_labels)
              if run_args.ordinal else None)
    batches = train_depth.TrainingBatches(train_depth.make_source(run_args.data, size), run_args, size,
                                          ckpt["step"], photos)
    print(f"{args.checkpoint} (step {ckpt['step']}), {run_args.model}")
    for k in range(args.batches):
        rgb, disp, _, real = batches[k]
        scores = agreement(model, (rgb, disp, *real[0]), run_args)
        print(f"batch {k}: " + ", ".join(f"{name} {value:.4f}" for name, value in scores.items()), flush=True)


if __name__ == "__main__":
    main()

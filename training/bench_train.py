"""Training throughput of the depth network: samples per hour at 256x192 (forward,
backward, optimiser and data included), for the old ways (one thread, scenes made in the
loop; glibc's malloc thresholds left as they are) and the current one (every core,
batches made ahead by a worker, freed blocks kept by training/malloc_reuse.py), written
to training/BENCH_TRAIN.md; then the long runs' batch (4 scenes + 8 real photos) in fp32
and, where the processor has bfloat16 instructions, under train_depth.py --bf16, for each
network.

    /usr/bin/python3 training/bench_train.py [--steps 20] [--model lite]

Each row is a short real run of train_depth.py in a temporary folder and a process of its
own, timed from the end of its first step to the end of its last (start-up, validation and
checkpoints left out).
The rows run one after another on one machine: compare them with each other, and say how
busy the machine was (the load average is printed into the table).
"""
from __future__ import annotations

import argparse
import multiprocessing
import os
import platform
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import train_depth  # noqa: E402

HERE = Path(__file__).resolve().parent
TABLE = HERE / "BENCH_TRAIN.md"
ORDINAL = HERE / "ordinal" / "ordinal.json.gz"


def configurations(cores: int):
    """(name, train_depth arguments) of each row."""
    rows = [("1 thread, scenes in the loop, batch 4, glibc's malloc thresholds (the first setup)",
             ["--threads", "1", "--workers", "0", "--batch", "4", "--malloc-defaults"]),
            (f"{cores} threads, 1 worker, batch 8 scenes",
             ["--threads", str(cores), "--workers", "1", "--batch", "8"])]
    if ORDINAL.exists():
        photos = ["--threads", str(cores), "--workers", "1", "--batch", "4", "--ordinal", str(ORDINAL)]
        rows.append((f"{cores} threads, 1 worker, batch 4 scenes + 4 real photos (ranking loss), "
                     "glibc's malloc thresholds (the setup before malloc_reuse.py)", photos + ["--malloc-defaults"]))
        rows.append((f"{cores} threads, 1 worker, batch 4 scenes + 4 real photos (ranking loss)", photos))
    return rows


def precisions():
    """(name, train_depth arguments) of fp32 and, where the processor runs bfloat16 dot
    products in hardware, bf16 autocast: elsewhere it is emulated and only slower."""
    rows = [("fp32", [])]
    if cpu_flags() & {"avx512_bf16", "amx_bf16"}:
        rows.append(("bf16 autocast (`--bf16`)", ["--bf16"]))
    return rows


def cpu_flags() -> set:
    return set(cpuinfo("flags", "Features").split())   # x86's name, then Arm's


def processor_name() -> str:
    return cpuinfo("model name") or platform.machine()


def cpuinfo(*keys: str) -> str:
    """The value of the first /proc/cpuinfo line starting with one of keys ('' if none)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith(keys):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return ""


def measure(model: str, size: str, steps: int, extra):
    """One row, in a process of its own (forked from this one, which never trains): the
    malloc settings (training/malloc_reuse.py) and the thread pools of one row must not
    carry over to the next."""
    with tempfile.TemporaryDirectory() as run:
        argv = ["--model", model, "--run", run, "--data", "scenes", "--size", size,
                "--steps", str(steps + 1), "--val-every", str(10 ** 9), "--val-count", "1",
                "--checkpoint-every", str(10 ** 9), "--log-every", str(10 ** 9)] + extra
        with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:
            result = pool.submit(train_depth.main, argv).result()
    seconds_per_step = result["seconds"] / result["steps"]
    return seconds_per_step, 3600 * result["samples_per_step"] / seconds_per_step


def timed_row(name: str, model: str, args, extra) -> str:
    seconds, rate = measure(model, args.size, args.steps, extra)
    row = f"| {name} | {seconds:.2f} | {rate:,.0f} |"
    print(row, flush=True)
    return row


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--model", default="lite")
    p.add_argument("--size", default="256x192")
    p.add_argument("--steps", type=int, default=20, help="timed steps per row")
    p.add_argument("--output", default=str(TABLE))
    args = p.parse_args()
    cores = os.cpu_count() or 1
    rows = [timed_row(name, args.model, args, extra) for name, extra in configurations(cores)]
    long_runs = ["--threads", str(cores), "--workers", "1", "--batch", "4", "--ordinal", str(ORDINAL),
                 "--ordinal-batch", "8"]
    precision_rows = [timed_row(f"{model}, {name}", model, args, long_runs + extra)
                      for model in ("lite", "heavy") for name, extra in precisions()] if ORDINAL.exists() else []
    load = " / ".join(f"{v:.1f}" for v in os.getloadavg())
    text = "\n".join([
        "# Depth training throughput",
        "",
        f"`/usr/bin/python3 training/bench_train.py --model {args.model} --steps {args.steps}`, "
        f"{time.strftime('%Y-%m-%d')}, {processor_name()}, {cores} cores, "
        f"load average after the run {load} (1/5/15 min).",
        "",
        f"{args.model} at {args.size}: forward, backward, Adam and data, timed over {args.steps} steps after the first.",
        "",
        "| setup | s/step | samples/hour |",
        "|---|---:|---:|",
        *rows,
        "",
        f"The long runs' batch at {args.size}: {cores} threads, 1 worker, 4 scenes + 8 real photos (ranking loss).",
        "",
        "| network, precision | s/step | samples/hour |",
        "|---|---:|---:|",
        *precision_rows,
        "",
    ])
    Path(args.output).write_text(text)
    print(f"{args.output} written")


if __name__ == "__main__":
    main()

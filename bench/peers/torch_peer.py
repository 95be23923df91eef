"""PyTorch (Debian's python3-torch, CPU) running a depth network from its .ampw file,
BatchNorm folded (peer_net.py): one of the peers bench/peers/run.sh puts beside
`ampi bench network`. Same protocol as the other peers: a 1 x 3 x H x W float32 .npy
input, one JSON line per thread count on stdout, the output saved as H x W .npy.

    /usr/bin/python3 bench/peers/torch_peer.py --weights weights/depth_lite.ampw --input rgb_nchw.npy --threads 1,2

PyTorch runs in inference mode with the channels_last memory format (NHWC, like ampi),
which is faster than the default NCHW on this project's machines for these networks
(bench/peers/README.md); --memory-format contiguous gives the default.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peer_net  # noqa: E402

FORMATS = {"channels_last": torch.channels_last, "contiguous": torch.contiguous_format}


def thread_list(text: str):
    counts = [int(v) for v in text.split(",")]
    if any(n < 1 for n in counts):
        raise argparse.ArgumentTypeError(f"bad thread list '{text}'")
    return counts


def timed_runs(model, x, warmup: int, runs: int):
    with torch.inference_mode():
        for _ in range(warmup):
            out = model(x)
        ms = []
        for _ in range(runs):
            start = time.perf_counter()
            out = model(x)
            ms.append((time.perf_counter() - start) * 1e3)
    return ms, out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--weights", required=True, help="a depth .ampw file")
    p.add_argument("--input", required=True, help="1 x 3 x H x W float32 .npy, RGB in [0, 1]")
    p.add_argument("--threads", type=thread_list, default=[1, 2])
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--warmup", type=int, default=1)
    p.add_argument("--save", default="", help="writes PREFIX.tT.npy per thread count T")
    p.add_argument("--memory-format", choices=sorted(FORMATS), default="channels_last")
    args = p.parse_args(argv)

    rgb = np.load(args.input)
    if rgb.ndim != 4 or rgb.shape[:2] != (1, 3) or rgb.dtype != np.float32:
        raise SystemExit(f"torch_peer.py: {args.input}: expected a float32 1 x 3 x H x W array, "
                         f"got {rgb.dtype} {rgb.shape}")
    fmt = FORMATS[args.memory_format]
    model = peer_net.load(args.weights).to(memory_format=fmt)
    x = torch.from_numpy(rgb).contiguous(memory_format=fmt)
    torch.set_num_interop_threads(1)
    for threads in args.threads:
        torch.set_num_threads(threads)
        ms, out = timed_runs(model, x, args.warmup, max(1, args.runs))
        print(json.dumps({"engine": "pytorch", "version": torch.__version__, "threads": threads,
                          "memory_format": args.memory_format, "ms": ms}), flush=True)
        if args.save:
            np.save(f"{args.save}.t{threads}.npy", np.ascontiguousarray(out[0, 0].numpy()))


if __name__ == "__main__":
    main()

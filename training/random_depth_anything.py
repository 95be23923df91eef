"""Writes a Depth Anything V2 checkpoint with seeded random weights, for trying the
importer and the engine without the real download (no quality, the same shapes).

    /usr/bin/python3 training/random_depth_anything.py vits /tmp/dav2_random_vits.pth [--seed N]
    /usr/bin/python3 training/import_depth_anything.py /tmp/dav2_random_vits.pth /tmp/dav2_random_vits.ampw

The file is a plain state dict with the official key names and shapes (the twin's,
depth_anything.py), so it goes through exactly the path a downloaded
depth_anything_v2_vits.pth takes. The weights are those check_depth_anything.py gives the
official model (depth_anything.randomise_).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import depth_anything as dav2  # noqa: E402

SEED = 20240613


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("variant", choices=sorted(dav2.VARIANTS))
    p.add_argument("output", help="the .pth file to write")
    p.add_argument("--seed", type=int, default=SEED)
    args = p.parse_args(argv)
    model = dav2.randomise_(dav2.build(args.variant), args.seed)
    torch.save(model.state_dict(), args.output)
    count = sum(t.numel() for t in model.state_dict().values())
    print(f"{args.output}: random {args.variant}, seed {args.seed}, {count:,} parameters")


if __name__ == "__main__":
    main()

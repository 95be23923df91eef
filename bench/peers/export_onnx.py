"""Exports a depth weight file (.ampw) to ONNX, BatchNorm folded, for ONNX Runtime and
OpenCV DNN, at one fixed input size (static shapes: OpenCV 4.6's importer and ONNX
Runtime's optimiser both do best with them).

    /usr/bin/python3 bench/peers/export_onnx.py weights/depth_lite.ampw out/peers/lite_384x512.onnx --size 512x384

Input "rgb" [1, 3, H, W] in [0, 1]; output "disparity" [1, 1, H, W]. H and W must be
multiples of the network's multiple (32 for the bundled files). Refuses to leave a file
behind that still holds a BatchNormalization node.
"""
from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peer_net  # noqa: E402

OPSET = 13


def parse_size(text: str):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size '{text}' is not WxH")
    return w, h


def export(ampw: str, onnx_path: str, width: int, height: int) -> None:
    model = peer_net.load(ampw)
    multiple = model.multiple
    if width % multiple or height % multiple:
        raise SystemExit(f"export_onnx.py: {width}x{height} is not a multiple of {multiple}")
    tmp = onnx_path + ".tmp"
    with warnings.catch_warnings(), torch.no_grad():
        warnings.simplefilter("ignore")  # tracer warnings about the size check
        torch.onnx.export(model, torch.rand(1, 3, height, width), tmp, opset_version=OPSET,
                          input_names=["rgb"], output_names=["disparity"], do_constant_folding=True)
    if b"BatchNormalization" in Path(tmp).read_bytes():
        os.remove(tmp)
        raise SystemExit(f"export_onnx.py: {onnx_path}: the export still holds a BatchNormalization node")
    os.replace(tmp, onnx_path)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("weights", help="a depth .ampw file")
    p.add_argument("output", help="the .onnx file to write")
    p.add_argument("--size", type=parse_size, required=True, help="input WxH")
    args = p.parse_args(argv)
    if not Path(args.weights).is_file():
        raise SystemExit(f"export_onnx.py: {args.weights}: no such file")
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    export(args.weights, args.output, *args.size)


if __name__ == "__main__":
    main()

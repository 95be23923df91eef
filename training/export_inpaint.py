"""Exports the inpainting generator to an .ampw file for the C++ engine, and writes the
parity fixtures the C++ tests compare against.

File contents (read by nets/inpaint_net.cpp):
  metadata  arch = "ampi.inpaint.gated-conv", inpaint.version (1: hole zeroed, output the fill;
            2: hole pre-filled by the fill named in inpaint.prefill, output a residual
            on it inside the hole; training/inpaint_model.py), the graph of
            training/inpaint_model.py as parallel int arrays (inpaint.source, .upsample,
            .skip, .in_channels, .out_channels, .kernel, .stride, .dilation, .gated),
            inpaint.layer_names (comma-separated), inpaint.feature_activation,
            inpaint.output_activation, inpaint.multiple, and where the weights came from
            (training.*).
  tensors   NAME.weight OHWI [out][k][k][in] (PyTorch's OIHW transposed; a gated layer's
            2c outputs are the c feature channels, then the c gate channels), NAME.bias
            [out]. The generator has no BatchNorm, so there is nothing to fold.

Fixtures (tests/fixtures/inpaint/):
  bad_*.ampw, no_tensors.ampw  metadata-only files the loader must reject;
  tiny.ampw + tiny_case.ampw   the same graph with fewer channels and seeded random
                               weights, and one input/output pair from PyTorch;
  tiny_push_pull.ampw          tiny.ampw naming the push-pull prefill;
  bundled_case.ampw            an input/output pair for the exported weights themselves;
  push_pull_*.ampw,            images, masks and training/inpaint_push_pull.py's fill,
  harmonic_*.ampw              for the C++ push-pull and harmonic fill to match (the
                               cascade ones name their coarsest_side).
A case file holds rgb [h][w][3] in [-1, 1], hole [h][w] in {0, 1} and expected [h][w][3].

    /usr/bin/python3 training/export_inpaint.py --checkpoint training/runs/inpaint/best.pt
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np
import torch

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)
import inpaint_model as im  # noqa: E402
import inpaint_push_pull  # noqa: E402
from weights_format.ampw import write_ampw  # noqa: E402

FIXTURES = os.path.join(ROOT, "tests", "fixtures", "inpaint")
ARCH_NAME = "ampi.inpaint.gated-conv"  # nets/architectures.h
CASE_HEIGHT, CASE_WIDTH = 28, 36  # multiples of 4, not square, small enough for qemu


def narrow_layers(layers, divisor: int):
    """The same graph with out_channels divided (the output layer keeps its 3)."""
    last = len(layers) - 1
    return [row if i == last else row[:4] + (max(2, row[4] // divisor),) + row[5:]
            for i, row in enumerate(layers)]


def graph_metadata(layers, version: int = 2, prefill: str = im.PREFILL):
    names = [row[0] for row in layers]
    if any("," in n for n in names):
        raise ValueError("layer names may not contain commas")
    cols = list(zip(*layers))
    return {
        "arch": ARCH_NAME,
        "inpaint.version": version,
        **({"inpaint.prefill": prefill} if version == 2 else {}),
        "inpaint.layer_names": ",".join(names),
        "inpaint.source": list(cols[1]),
        "inpaint.upsample": list(cols[2]),
        "inpaint.skip": list(cols[3]),
        "inpaint.in_channels": im.layer_in_channels(layers),
        "inpaint.out_channels": list(cols[4]),
        "inpaint.kernel": list(cols[5]),
        "inpaint.stride": list(cols[6]),
        "inpaint.dilation": list(cols[7]),
        "inpaint.gated": list(cols[8]),
        "inpaint.feature_activation": im.FEATURE_ACTIVATION,
        "inpaint.output_activation": im.OUTPUT_ACTIVATION,
        "inpaint.multiple": im.MULTIPLE,
        "inpaint.input": (f"rgb/127.5-1 with the {prefill} fill in the hole, then the hole mask (1 = unknown)"
                          if version == 2 else
                          "rgb/127.5-1 with the hole zeroed, then the hole mask (1 = unknown)"),
    }


def generator_tensors(g: im.InpaintGenerator):
    tensors = {}
    for (name, *_rest), module in zip(g.layers_spec, g.convs):
        conv = module.conv if isinstance(module, im.GatedConv) else module
        w = conv.weight.detach().numpy()
        tensors[name + ".weight"] = np.ascontiguousarray(w.transpose(0, 2, 3, 1), dtype=np.float32)
        tensors[name + ".bias"] = conv.bias.detach().numpy().astype(np.float32)
    return tensors


def import_ampw(path: str) -> im.InpaintGenerator:
    """The generator of an exported file (the inverse of export): what lets a run on a
    fresh checkout start from the bundled weights, which have no checkpoint beside them."""
    from weights_format.ampw import read_ampw
    meta, tensors = read_ampw(path)
    if meta.get("arch") != ARCH_NAME:
        raise ValueError(f"{path}: architecture {meta.get('arch')!r} is not {ARCH_NAME}")
    g = im.InpaintGenerator(residual=int(meta["inpaint.version"]) == 2)
    if meta["inpaint.layer_names"] != ",".join(row[0] for row in g.layers_spec):
        raise ValueError(f"{path}: its graph is not training/inpaint_model.py's LAYERS")
    with torch.no_grad():
        for (name, *_rest), module in zip(g.layers_spec, g.convs):
            conv = module.conv if isinstance(module, im.GatedConv) else module
            conv.weight.copy_(torch.from_numpy(tensors[name + ".weight"].transpose(0, 3, 1, 2).copy()))
            conv.bias.copy_(torch.from_numpy(tensors[name + ".bias"]))
    return g


def export(g: im.InpaintGenerator, path: str, extra_metadata=None, prefill: str = im.PREFILL):
    meta = graph_metadata(g.layers_spec, g.version, prefill)
    meta.update(extra_metadata or {})
    write_ampw(path, generator_tensors(g), meta)


def case_input(seed: int):
    """A random image and a hole mask with the shapes MPI margins have: a filled blob,
    a thin band and scattered pixels."""
    rng = np.random.default_rng(seed)
    h, w = CASE_HEIGHT, CASE_WIDTH
    rgb = rng.uniform(-1, 1, (1, 3, h, w)).astype(np.float32)
    yy, xx = np.mgrid[0:h, 0:w]
    hole = ((yy - 10) ** 2 + (xx - 22) ** 2 < 60) | ((xx > 4) & (xx < 8)) | (rng.random((h, w)) < 0.05)
    return torch.from_numpy(rgb), torch.from_numpy(hole.astype(np.float32))[None, None]


def write_case(g: im.InpaintGenerator, path: str, seed: int):
    rgb, hole = case_input(seed)
    with torch.no_grad():
        out = g.eval()(rgb, hole)
    nhwc = lambda t: np.ascontiguousarray(t[0].numpy().transpose(1, 2, 0))  # noqa: E731
    write_ampw(path, {"rgb": nhwc(rgb), "hole": hole[0, 0].numpy().copy(), "expected": nhwc(out)},
               {"seed": seed})


def write_tiny_fixture():
    torch.manual_seed(7)
    g = im.InpaintGenerator(narrow_layers(im.LAYERS, 4))
    # random init is small; larger weights make every layer matter in the comparison
    with torch.no_grad():
        torch.nn.init.normal_(g.convs[-1].weight, std=0.1)  # not the zero start: test it all
        torch.nn.init.normal_(g.convs[-1].bias, std=0.1)
        for p in g.parameters():
            p.mul_(2.0)
    source = {"training.source": "seeded random weights (fixture)"}
    export(g, os.path.join(FIXTURES, "tiny.ampw"), source)
    export(g, os.path.join(FIXTURES, "tiny_push_pull.ampw"), source, prefill="push-pull")
    write_case(g, os.path.join(FIXTURES, "tiny_case.ampw"), seed=11)


def write_prefill_fixtures():
    """Both prefills at odd, even and tiny sizes: INTER_AREA's fractional cells, the
    1-pixel levels, the relaxation's image edges; and the harmonic cascade, which real
    photos take above 1024 px, on small images through a small coarsest side."""
    for method in inpaint_push_pull.PREFILLS:
        for size, seed, h, w in (("odd", 21, 37, 53), ("even", 22, 64, 48), ("thin", 23, 5, 19)):
            name = f"{method.replace('-', '_')}_{size}.ampw"
            inpaint_push_pull.write_fixture(os.path.join(FIXTURES, name), seed, h, w, method)
    for size, seed, h, w in (("odd", 24, 37, 53), ("even", 25, 64, 48)):
        inpaint_push_pull.write_fixture(os.path.join(FIXTURES, f"harmonic_cascade_{size}.ampw"), seed, h, w,
                                        "harmonic", coarsest_side=12, start_side=30, band=3,
                                        coarsest_sweeps=3, sweeps=2)  # few: the start shows


def write_bad_fixtures():
    """Metadata-only files the loader must reject with a message naming the problem."""
    meta = graph_metadata(narrow_layers(im.LAYERS, 4))
    bad_channels = dict(meta, **{"inpaint.in_channels": [4, 5] + meta["inpaint.in_channels"][2:]})
    write_ampw(os.path.join(FIXTURES, "bad_channels.ampw"), {}, bad_channels)
    bad_source = dict(meta, **{"inpaint.source": [-1, 3] + meta["inpaint.source"][2:]})
    write_ampw(os.path.join(FIXTURES, "bad_source.ampw"), {}, bad_source)
    huge = 1 << 30  # padding dilation * (kernel - 1) / 2 would overflow an int
    bad_dilation = dict(meta, **{"inpaint.dilation": [huge] + meta["inpaint.dilation"][1:]})
    write_ampw(os.path.join(FIXTURES, "bad_dilation.ampw"), {}, bad_dilation)
    bad_prefill = dict(meta, **{"inpaint.prefill": "telea"})
    write_ampw(os.path.join(FIXTURES, "bad_prefill.ampw"), {}, bad_prefill)
    write_ampw(os.path.join(FIXTURES, "no_tensors.ampw"), {}, meta)


def main(argv=None):
    ap = argparse.ArgumentParser(description="export the inpainting generator")
    ap.add_argument("--checkpoint", default=os.path.join(HERE, "runs", "inpaint", "best.pt"))
    ap.add_argument("--out", default=os.path.join(ROOT, "weights", "inpaint.ampw"))
    ap.add_argument("--disparity", default="stand-in", help="what sliced the training photos")
    ap.add_argument("--tiny-only", action="store_true", help="only rewrite the tiny fixture")
    args = ap.parse_args(argv)
    os.makedirs(FIXTURES, exist_ok=True)
    write_tiny_fixture()
    write_bad_fixtures()
    write_prefill_fixtures()
    if args.tiny_only:
        return 0
    ck = torch.load(args.checkpoint, map_location="cpu")
    g = im.InpaintGenerator(residual=ck.get("residual", False))  # the first runs had none
    g.load_state_dict(ck["generator"])
    # checkpoints name the prefill they trained on; those from before v5 had push-pull
    export(g, args.out, prefill=ck.get("prefill", "push-pull"), extra_metadata={
        "training.steps": int(ck["step"]),
        "training.val_psnr": float(ck.get("val_psnr", ck.get("best_psnr", float("nan")))),
        "training.disparity": args.disparity,
        "training.source": os.path.basename(args.checkpoint),
    })
    write_case(g, os.path.join(FIXTURES, "bundled_case.ampw"), seed=12)
    print(f"wrote {args.out} (step {ck['step']}) and the fixtures in {FIXTURES}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

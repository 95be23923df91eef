"""Exports a trained depth network to ampi's weight file (.ampw), ready for nets/depth_net.

    /usr/bin/python3 training/export_depth.py training/runs/lite/checkpoint.pt weights/depth_lite.ampw [--averaged]

What the file holds (nets/ARCHITECTURE.md describes the graph these rebuild):
  - every convolution with its BatchNorm folded in (w' = w * g / sqrt(v + eps),
    b' = beta - m * g / sqrt(v + eps)), weights in OHWI order ([out][kh][kw][in/groups]),
    f32; squeeze-excite layers as 2-D matrices fc1 [reduced][channels], fc2 [channels][reduced];
  - metadata: the architecture name and every hyper-parameter the C++ builder needs
    (levels, the block list of each encoder and decoder level, head kernel, input
    multiple), the input normalisation, the working resolution the weights suit, the format version, and where the weights come
    from (the git commit of the training code, steps, data).

Tensor names: enc{L}.{i}.{part} and dec{L}.{i}.{part} with levels L counted from 1 (half
resolution) and block index i from 0; parts `conv` (plain conv block) or `expand`, `dw`,
`se.fc1`, `se.fc2`, `project` (MobileNetV3 block), each with `.weight` and `.bias`;
the heads head{L}.weight / head{L}.bias on decoder levels 1..4.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
import torch
import torch.nn as nn

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "weights_format"))
import depth_model  # noqa: E402
from ampw import write_ampw  # noqa: E402

ARCH_NAME = "ampi.depth.dwt-mobilenetv3"
FORMAT_VERSION = 1
KIND_CODES = {depth_model.CONV: 0, depth_model.MB: 1}
ACT_CODES = {depth_model.NONE: 0, depth_model.RELU: 1, depth_model.HSWISH: 2}
FIELDS_PER_BLOCK = 6  # kind, out, expanded, kernel, se_reduced (0: none), activation


def fold_conv_bn(conv: nn.Conv2d, bn: nn.BatchNorm2d | None):
    """(OHWI weight, bias) of the convolution with the BatchNorm after it folded in."""
    w = conv.weight.detach().double()
    b = conv.bias.detach().double() if conv.bias is not None else torch.zeros(w.shape[0], dtype=torch.float64)
    if bn is not None:
        scale = bn.weight.detach().double() / torch.sqrt(bn.running_var.double() + bn.eps)
        w = w * scale.view(-1, 1, 1, 1)
        b = (b - bn.running_mean.double()) * scale + bn.bias.detach().double()
    return w.permute(0, 2, 3, 1).float().numpy().copy(), b.float().numpy().copy()


def block_codes(spec):
    kind, out_c, exp_c, kernel, se, act = spec
    reduced = depth_model.se_reduced_channels(exp_c) if (kind == depth_model.MB and se) else 0
    return [KIND_CODES[kind], out_c, exp_c, kernel, reduced, ACT_CODES[act]]


def block_tensors(prefix: str, block: nn.Module, tensors: dict):
    def put(name, conv, bn):
        tensors[f"{prefix}.{name}.weight"], tensors[f"{prefix}.{name}.bias"] = fold_conv_bn(conv, bn)

    if isinstance(block, depth_model.ConvBN):
        put("conv", block.conv, block.bn)
        return
    if block.expand is not None:
        put("expand", block.expand.conv, block.expand.bn)
    put("dw", block.dw.conv, block.dw.bn)
    if block.se is not None:
        for fc in ("fc1", "fc2"):
            layer = getattr(block.se, fc)
            tensors[f"{prefix}.se.{fc}.weight"] = layer.weight.detach()[:, :, 0, 0].numpy().copy()
            tensors[f"{prefix}.se.{fc}.bias"] = layer.bias.detach().numpy().copy()
    put("project", block.project.conv, block.project.bn)


def stage_metadata(specs):
    return [code for spec in specs for code in block_codes(spec)]


def git_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], cwd=HERE, capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def export(model: depth_model.DepthNet, path: str, provenance: dict, working_long_side: int = 1024):
    model.eval()
    arch = model.arch
    tensors = {}
    meta = {
        "arch": ARCH_NAME,
        "depth.format_version": FORMAT_VERSION,
        "depth.variant": arch["name"],
        "depth.levels": len(arch["encoder"]),
        "depth.multiple": model.multiple,
        "depth.outputs": depth_model.NUM_OUTPUTS,
        "depth.head_kernel": arch["head_kernel"],
        "depth.working_long_side": int(working_long_side),
        "depth.block_fields": "kind(0 conv, 1 mobilenetv3), out, expanded, kernel, se_reduced(0 none), "
                              "act(0 none, 1 relu, 2 hardswish)",
        "depth.input": "RGB in [0, 1], x' = (x - mean) / std per channel; H, W multiples of depth.multiple",
        "depth.input_mean": [float(v) for v in depth_model.INPUT_MEAN],
        "depth.input_std": [float(v) for v in depth_model.INPUT_STD],
        "depth.output": "relative disparity (larger = nearer), trained against targets in [0, 10]",
    }
    for level, (specs, stage) in enumerate(zip(arch["encoder"], model.enc), start=1):
        meta[f"depth.encoder.{level}"] = stage_metadata(specs)
        for i, block in enumerate(stage):
            block_tensors(f"enc{level}.{i}", block, tensors)
    for level, (specs, stage) in enumerate(zip(arch["decoder"], model.dec), start=1):
        meta[f"depth.decoder.{level}"] = stage_metadata(specs)
        for i, block in enumerate(stage):
            block_tensors(f"dec{level}.{i}", block, tensors)
    for level, head in enumerate(model.heads, start=1):
        tensors[f"head{level}.weight"], tensors[f"head{level}.bias"] = fold_conv_bn(head, None)
    meta.update({f"train.{k}": v for k, v in provenance.items()})
    meta["train.commit"] = git_commit()
    meta["depth.parameters"] = int(sum(t.size for t in tensors.values()))
    write_ampw(path, tensors, meta)
    return meta


def _specs_from_codes(codes):
    kinds = {v: k for k, v in KIND_CODES.items()}
    acts = {v: k for k, v in ACT_CODES.items()}
    codes = [int(c) for c in codes]
    return [(kinds[codes[i]], codes[i + 1], codes[i + 2], codes[i + 3], int(codes[i + 4] > 0), acts[codes[i + 5]])
            for i in range(0, len(codes), FIELDS_PER_BLOCK)]


def _set_conv(conv: nn.Conv2d, bn: nn.BatchNorm2d | None, weight, bias):
    """Loads a folded (OHWI weight, bias) pair; a BatchNorm left behind becomes a pure
    shift (gamma 1, var 1 - eps, mean 0), so the module computes exactly conv + bias."""
    conv.weight.data.copy_(torch.from_numpy(np.asarray(weight)).permute(0, 3, 1, 2))
    target = conv if bn is None else bn
    if bn is not None:
        bn.weight.data.fill_(1.0)
        bn.running_mean.zero_()
        bn.running_var.fill_(1.0 - bn.eps)
    target.bias.data.copy_(torch.from_numpy(np.asarray(bias)))


def import_ampw(path: str) -> depth_model.DepthNet:
    """The PyTorch network of an exported file (folded weights), in eval mode: the
    reference the C++ parity fixtures are computed with."""
    from ampw import read_ampw
    meta, tensors = read_ampw(path)
    if meta.get("arch") != ARCH_NAME:
        raise ValueError(f"{path}: architecture {meta.get('arch')!r} is not {ARCH_NAME}")
    levels = int(meta["depth.levels"])
    arch = {"name": meta["depth.variant"], "head_kernel": int(meta["depth.head_kernel"]),
            "encoder": [_specs_from_codes(meta[f"depth.encoder.{l}"]) for l in range(1, levels + 1)],
            "decoder": [_specs_from_codes(meta[f"depth.decoder.{l}"]) for l in range(1, levels)]}
    model = depth_model.DepthNet(arch)
    for prefix, stages in (("enc", model.enc), ("dec", model.dec)):
        for level, stage in enumerate(stages, start=1):
            for i, block in enumerate(stage):
                name = f"{prefix}{level}.{i}"
                if isinstance(block, depth_model.ConvBN):
                    _set_conv(block.conv, block.bn, tensors[f"{name}.conv.weight"], tensors[f"{name}.conv.bias"])
                    continue
                parts = [("dw", block.dw), ("project", block.project)]
                if block.expand is not None:
                    parts.append(("expand", block.expand))
                for part, layer in parts:
                    _set_conv(layer.conv, layer.bn, tensors[f"{name}.{part}.weight"], tensors[f"{name}.{part}.bias"])
                if block.se is not None:
                    for fc in ("fc1", "fc2"):
                        layer = getattr(block.se, fc)
                        layer.weight.data.copy_(torch.from_numpy(tensors[f"{name}.se.{fc}.weight"])[:, :, None, None])
                        layer.bias.data.copy_(torch.from_numpy(tensors[f"{name}.se.{fc}.bias"]))
    for level, head in enumerate(model.heads, start=1):
        _set_conv(head, None, tensors[f"head{level}.weight"], tensors[f"head{level}.bias"])
    return model.eval()


def unfold_batchnorm(model: depth_model.DepthNet, batches) -> depth_model.DepthNet:
    """Makes a network imported from folded weights (import_ampw) trainable again.

    Folding leaves every BatchNorm a pure shift, but training normalises with batch
    statistics, which would change what the network computes. Each BatchNorm instead gets
    the mean and variance of its input over `batches`, with gamma and beta chosen so that
    in eval mode it still computes exactly the folded conv + bias; in training mode the
    batch statistics then stay close to those. This is what lets a run continue from the
    bundled .ampw (a new checkout has no checkpoint)."""
    sums = {}

    def record(bn, inputs, _output):
        x = inputs[0].double()
        s = sums.setdefault(bn, [0.0, 0.0, 0])
        s[0] = s[0] + x.sum(dim=(0, 2, 3))
        s[1] = s[1] + (x * x).sum(dim=(0, 2, 3))
        s[2] += x.numel() // x.shape[1]

    norms = [m for m in model.modules() if isinstance(m, nn.BatchNorm2d)]
    hooks = [bn.register_forward_hook(record) for bn in norms]
    model.eval()
    with torch.no_grad():
        for batch in batches:
            model(batch)
    for hook in hooks:
        hook.remove()
    with torch.no_grad():
        for bn in norms:
            total, squares, count = sums[bn]
            mean = total / count
            var = (squares / count - mean * mean).clamp_min(1e-8)
            shift = bn.bias.double() - bn.weight.double() * bn.running_mean.double() / torch.sqrt(
                bn.running_var.double() + bn.eps)  # what the folded BatchNorm adds now
            bn.running_mean.copy_(mean)
            bn.running_var.copy_(var)
            bn.weight.copy_(torch.sqrt(var + bn.eps))
            bn.bias.copy_(shift + mean)
    return model


def load_checkpoint(path: str, averaged: bool = False):
    """The network of a train_depth.py checkpoint and the checkpoint; with averaged, the
    weight average a checkpoint.pt of an --ema run keeps beside the raw weights (what its
    validations measured), not the raw weights."""
    ckpt = torch.load(path, map_location="cpu", weights_only=False)
    if averaged and "ema" not in ckpt:
        raise SystemExit(f"{path}: no weight average (a checkpoint.pt of a run with --ema has one)")
    model = depth_model.build(ckpt["model_name"])
    model.load_state_dict(ckpt["ema" if averaged else "model"])
    return model, ckpt


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("checkpoint", help="train_depth.py checkpoint.pt or best.pt")
    p.add_argument("output", help="the .ampw file to write")
    p.add_argument("--data", default="", help="what the network was trained on (recorded in the metadata)")
    p.add_argument("--working-long-side", type=int, default=1024,
                   help="the long side inference should run at by default (a network trained on small "
                        "images generalises to a few times its training size, not to any)")
    p.add_argument("--averaged", action="store_true",
                   help="export a checkpoint.pt's weight average (--ema), not its raw weights")
    args = p.parse_args(argv)
    model, ckpt = load_checkpoint(args.checkpoint, args.averaged)
    provenance = {"steps": int(ckpt["step"]), "data": args.data,
                  "best_val_loss": float(ckpt.get("best_val", ckpt.get("val_loss")))}
    if ckpt.get("ordinal_whdr") is not None:  # a best.pt kept by the ordinal validation
        provenance["ordinal_val_whdr"] = float(ckpt["ordinal_whdr"])
    meta = export(model, args.output, provenance, args.working_long_side)
    size = Path(args.output).stat().st_size
    print(f"{args.output}: {meta['depth.variant']}, {meta['depth.parameters']} parameters, "
          f"{size / 1e6:.2f} MB, step {ckpt['step']}")


if __name__ == "__main__":
    main()

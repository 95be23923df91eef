"""The depth network of an .ampw file as the peers run it, in PyTorch: RGB [1, 3, H, W]
in [0, 1] -> disparity [1, 1, H, W], with `multiple` the sides must be multiples of.

Depth Anything V2 files (arch ampi.depth.dav2-vit-dpt) run as our twin of the reference
model (training/depth_anything.py) rebuilt from the file, LayerScale folded as the file
holds it. The bundled families:

training/export_depth.import_ampw rebuilds the PyTorch network from a weight file; the
file's convolutions already hold their BatchNorm, and import_ampw leaves each BatchNorm
module behind as a pure shift. Here every convolution absorbs its BatchNorm (whatever its
statistics) and the BatchNorm is dropped, so PyTorch computes exactly the convolutions
ampi computes, and the ONNX export has no BatchNormalization node (OpenCV 4.6's importer
rejects the de-duplicated identical BatchNorm constants an unfolded export holds).
"""
from __future__ import annotations

import sys
from pathlib import Path

import torch
import torch.nn as nn

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "training"))
import depth_model  # noqa: E402
import import_depth_anything  # noqa: E402
from export_depth import import_ampw  # noqa: E402

sys.path.insert(0, str(REPO / "weights_format"))
from ampw import read_ampw  # noqa: E402


def fold_batchnorm(conv: nn.Conv2d, bn: nn.BatchNorm2d) -> None:
    """conv <- bn(conv(.)) in place: w * g / sqrt(v + eps), (b - m) * g / sqrt(v + eps) + beta."""
    with torch.no_grad():
        scale = bn.weight.double() / torch.sqrt(bn.running_var.double() + bn.eps)
        bias = conv.bias.double() if conv.bias is not None else torch.zeros_like(scale)
        conv.weight.copy_((conv.weight.double() * scale.view(-1, 1, 1, 1)).float())
        conv.bias = nn.Parameter(((bias - bn.running_mean.double()) * scale + bn.bias.double()).float())


def fold_all(model: nn.Module) -> int:
    """Folds every ConvBN of `model`; returns how many BatchNorms it removed."""
    folded = 0
    for module in model.modules():
        if isinstance(module, depth_model.ConvBN) and isinstance(module.bn, nn.BatchNorm2d):
            fold_batchnorm(module.conv, module.bn)
            module.bn = nn.Identity()
            folded += 1
    return folded


class FinalDisparity(nn.Module):
    """The inference graph: RGB [1, 3, H, W] in [0, 1] -> disparity [1, 1, H, W].

    DepthNet.forward's wiring, but only the full-resolution head runs: the three coarser
    heads serve training alone, ampi never computes them, and PyTorch's eager mode would
    (an ONNX export drops them anyway as dead code)."""

    def __init__(self, net: depth_model.DepthNet):
        super().__init__()
        self.net = net
        self.multiple = net.multiple

    def forward(self, rgb):
        net = self.net
        x = (rgb - net.mean) / net.std
        skips = []
        for stage in net.enc:
            x = stage(depth_model.haar_dwt(x))
            skips.append(x)
        y = skips[-1]
        for i in reversed(range(len(net.dec))):
            y = net.dec[i](torch.cat([haar_idwt(y), skips[i]], dim=1))
        return haar_idwt(net.heads[0](y))


def haar_idwt(x):
    """depth_model.haar_idwt with the four bands split at a fixed channel count:
    torch.chunk exports as shape arithmetic (Shape, Gather, Div) that OpenCV 4.6's ONNX
    importer cannot parse; the arithmetic is the same."""
    bands = int(x.shape[1]) // 4
    ll, lh, hl, hh = torch.split(x, bands, dim=1)
    x00 = (ll + lh + hl + hh) * 0.5
    x01 = (ll - lh + hl - hh) * 0.5
    x10 = (ll + lh - hl - hh) * 0.5
    x11 = (ll - lh - hl + hh) * 0.5
    n, c, h, w = (int(v) for v in ll.shape)
    top = torch.stack([x00, x01], dim=4).reshape(n, c, h, 2 * w)
    bottom = torch.stack([x10, x11], dim=4).reshape(n, c, h, 2 * w)
    return torch.stack([top, bottom], dim=3).reshape(n, c, 2 * h, 2 * w)


class DepthAnythingDisparity(nn.Module):
    """Depth Anything V2 on an image whose sides are multiples of 14 (the working size the
    benchmark gives it, so no resize): normalisation, then the twin."""

    def __init__(self, model, mean, std):
        super().__init__()
        self.model = model
        self.multiple = model.cfg.patch_size
        self.register_buffer("mean", torch.tensor(mean, dtype=torch.float32).view(1, 3, 1, 1))
        self.register_buffer("std", torch.tensor(std, dtype=torch.float32).view(1, 3, 1, 1))

    def forward(self, rgb):
        return self.model((rgb - self.mean) / self.std)[:, None]


def load(ampw_path: str) -> nn.Module:
    meta = read_ampw(ampw_path)[0]
    if meta.get("arch") == import_depth_anything.ARCH_NAME:
        model = import_depth_anything.import_ampw(ampw_path)
        return DepthAnythingDisparity(model, meta["depth.input_mean"], meta["depth.input_std"]).eval()
    net = import_ampw(ampw_path)
    fold_all(net)
    return FinalDisparity(net).eval()

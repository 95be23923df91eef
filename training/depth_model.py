"""The depth network of the paper: MobileNetV3 blocks between Haar wavelet transforms.

Topology (see nets/ARCHITECTURE.md for the layer tables and why it follows the paper):

    x0  = normalise(rgb)                                   H     x W     x 3
    x_l = encoder_l(DWT(x_{l-1}))          l = 1..L        H/2^l x W/2^l x e_l
    y_L = x_L
    y_l = decoder_l(concat(IDWT(y_{l+1}), x_l))   l = L-1..1
    out_k = IDWT(head_l(y_l))              l = 4..1  ->  disparity at 1/8, 1/4, 1/2, 1

Every down-scaling is a Haar DWT (no strided convolution), every up-scaling an inverse
DWT (no interpolation), the skips join at the half-resolution levels and below, and the
four heads predict the four Haar coefficients of the next finer disparity map, so even the
full-resolution output is reached by an inverse DWT. Only the last output is used at
inference.

The architecture is data (`ARCHITECTURES`): the exporter writes it into the weight file and
the C++ builder (nets/depth_net.cpp) reads it back, so both sides build the same graph.
"""
from __future__ import annotations

import torch
import torch.nn as nn
import torch.nn.functional as F

# Block descriptions: (kind, out_channels, expanded_channels, kernel, squeeze_excite, act).
# kind "conv": kernel x kernel convolution + BN + act (expanded/se unused, written as 0).
# kind "mb": MobileNetV3 inverted residual; expanded == in_channels skips the expansion.
CONV, MB = "conv", "mb"
RELU, HSWISH, NONE = "relu", "hardswish", "none"

BLOCK_KINDS = (CONV, MB)
ACTIVATIONS = (NONE, RELU, HSWISH)

INPUT_MEAN = (0.5, 0.5, 0.5)  # applied to RGB scaled to [0, 1]: x' = (x - mean) / std
INPUT_STD = (0.25, 0.25, 0.25)
NUM_OUTPUTS = 4  # supervised scales; the heads sit on decoder levels 4, 3, 2, 1


def _lite():
    enc = [
        [(CONV, 16, 0, 3, 0, HSWISH), (MB, 16, 16, 3, 0, RELU)],
        [(MB, 24, 128, 3, 0, RELU), (MB, 24, 72, 3, 0, RELU)],
        [(MB, 40, 144, 5, 1, RELU), (MB, 40, 120, 5, 1, RELU), (MB, 40, 120, 5, 1, RELU)],
        [(MB, 80, 320, 3, 0, HSWISH), (MB, 80, 200, 3, 0, HSWISH), (MB, 80, 184, 3, 0, HSWISH),
         (MB, 112, 480, 3, 1, HSWISH), (MB, 112, 672, 3, 1, HSWISH)],
        [(MB, 160, 672, 5, 1, HSWISH), (MB, 160, 800, 5, 1, HSWISH)],
    ]
    dec = [
        [(MB, 24, 96, 3, 0, HSWISH), (MB, 24, 72, 3, 0, HSWISH)],
        [(MB, 32, 128, 3, 0, HSWISH), (MB, 32, 96, 3, 0, HSWISH)],
        [(MB, 64, 192, 5, 1, HSWISH), (MB, 64, 192, 5, 1, HSWISH)],
        [(MB, 112, 448, 3, 1, HSWISH), (MB, 112, 448, 3, 1, HSWISH)],
    ]
    return {"name": "lite", "encoder": enc, "decoder": dec, "head_kernel": 3}


def _heavy():
    enc = [
        [(CONV, 24, 0, 3, 0, HSWISH), (MB, 24, 24, 3, 0, RELU)],
        [(MB, 40, 192, 3, 0, RELU), (MB, 40, 120, 3, 0, RELU)],
        [(MB, 64, 240, 5, 1, RELU), (MB, 64, 192, 5, 1, RELU), (MB, 64, 192, 5, 1, RELU)],
        [(MB, 128, 512, 3, 0, HSWISH), (MB, 128, 320, 3, 0, HSWISH), (MB, 128, 320, 3, 0, HSWISH),
         (MB, 160, 640, 3, 1, HSWISH), (MB, 160, 960, 3, 1, HSWISH)],
        [(MB, 240, 960, 5, 1, HSWISH), (MB, 240, 960, 5, 1, HSWISH), (MB, 240, 1040, 5, 1, HSWISH)],
    ]
    dec = [
        [(MB, 32, 128, 3, 0, HSWISH), (MB, 32, 96, 3, 0, HSWISH)],
        [(MB, 48, 192, 3, 0, HSWISH), (MB, 48, 144, 3, 0, HSWISH)],
        [(MB, 96, 288, 5, 1, HSWISH), (MB, 96, 288, 5, 1, HSWISH)],
        [(MB, 160, 640, 3, 1, HSWISH), (MB, 160, 640, 3, 1, HSWISH)],
    ]
    return {"name": "heavy", "encoder": enc, "decoder": dec, "head_kernel": 3}


ARCHITECTURES = {"lite": _lite(), "heavy": _heavy()}


def make_divisible(value: float, divisor: int = 8) -> int:
    """MobileNet's channel rounding (used for the squeeze-excite width)."""
    rounded = max(divisor, int(value + divisor / 2) // divisor * divisor)
    if rounded < 0.9 * value:
        rounded += divisor
    return rounded


def se_reduced_channels(channels: int) -> int:
    return make_divisible(channels / 4)


def multiple_of(arch: dict) -> int:
    """Input height and width must be multiples of this: one factor 2 per DWT."""
    return 2 ** len(arch["encoder"])


# ---- Haar wavelet transforms (fixed, no parameters) ---------------------------------------

def haar_dwt(x: torch.Tensor) -> torch.Tensor:
    """[N, C, H, W] -> [N, 4C, H/2, W/2], channel blocks LL | LH | HL | HH (orthonormal)."""
    x00, x01 = x[:, :, 0::2, 0::2], x[:, :, 0::2, 1::2]
    x10, x11 = x[:, :, 1::2, 0::2], x[:, :, 1::2, 1::2]
    ll = (x00 + x01 + x10 + x11) * 0.5
    lh = (x00 - x01 + x10 - x11) * 0.5
    hl = (x00 + x01 - x10 - x11) * 0.5
    hh = (x00 - x01 - x10 + x11) * 0.5
    return torch.cat([ll, lh, hl, hh], dim=1)


def haar_idwt(x: torch.Tensor) -> torch.Tensor:
    """The exact inverse of haar_dwt: [N, 4C, H, W] -> [N, C, 2H, 2W]."""
    ll, lh, hl, hh = torch.chunk(x, 4, dim=1)
    x00 = (ll + lh + hl + hh) * 0.5
    x01 = (ll - lh + hl - hh) * 0.5
    x10 = (ll + lh - hl - hh) * 0.5
    x11 = (ll - lh - hl + hh) * 0.5
    n, c, h, w = ll.shape
    top = torch.stack([x00, x01], dim=-1).reshape(n, c, h, 2 * w)
    bottom = torch.stack([x10, x11], dim=-1).reshape(n, c, h, 2 * w)
    return torch.stack([top, bottom], dim=3).reshape(n, c, 2 * h, 2 * w)


# ---- layers -------------------------------------------------------------------------------

def activation_module(name: str) -> nn.Module:
    if name == RELU:
        return nn.ReLU(inplace=True)
    if name == HSWISH:
        return nn.Hardswish(inplace=True)
    if name == NONE:
        return nn.Identity()
    raise ValueError(f"unknown activation {name!r}")


class ConvBN(nn.Sequential):
    """Convolution without bias, BatchNorm, activation; 'same' padding, stride 1."""

    def __init__(self, in_c: int, out_c: int, kernel: int, act: str, groups: int = 1):
        super().__init__()
        self.conv = nn.Conv2d(in_c, out_c, kernel, padding=kernel // 2, groups=groups, bias=False)
        self.bn = nn.BatchNorm2d(out_c)
        self.act = activation_module(act)


class SqueezeExcite(nn.Module):
    """Global average, fc + ReLU, fc + hard-sigmoid, channel scale (MobileNetV3)."""

    def __init__(self, channels: int):
        super().__init__()
        reduced = se_reduced_channels(channels)
        self.fc1 = nn.Conv2d(channels, reduced, 1)
        self.fc2 = nn.Conv2d(reduced, channels, 1)

    def forward(self, x):
        s = F.adaptive_avg_pool2d(x, 1)
        s = F.hardsigmoid(self.fc2(F.relu(self.fc1(s))))
        return x * s


class InvertedResidual(nn.Module):
    """MobileNetV3 block: [1x1 expand + BN + act] -> kxk depthwise + BN + act -> [SE] ->
    1x1 project + BN (linear) -> + input when the shapes match."""

    def __init__(self, in_c: int, out_c: int, exp_c: int, kernel: int, se: bool, act: str):
        super().__init__()
        self.expand = ConvBN(in_c, exp_c, 1, act) if exp_c != in_c else None
        self.dw = ConvBN(exp_c, exp_c, kernel, act, groups=exp_c)
        self.se = SqueezeExcite(exp_c) if se else None
        self.project = ConvBN(exp_c, out_c, 1, NONE)
        self.residual = in_c == out_c

    def forward(self, x):
        y = self.expand(x) if self.expand is not None else x
        y = self.dw(y)
        if self.se is not None:
            y = self.se(y)
        y = self.project(y)
        return x + y if self.residual else y


def build_block(spec, in_c: int) -> nn.Module:
    kind, out_c, exp_c, kernel, se, act = spec
    if kind == CONV:
        return ConvBN(in_c, out_c, kernel, act)
    if kind == MB:
        return InvertedResidual(in_c, out_c, exp_c, kernel, bool(se), act)
    raise ValueError(f"unknown block kind {kind!r}")


def build_stage(specs, in_c: int):
    blocks = []
    for spec in specs:
        blocks.append(build_block(spec, in_c))
        in_c = spec[1]
    return nn.Sequential(*blocks), in_c


class DepthNet(nn.Module):
    def __init__(self, arch: dict):
        super().__init__()
        self.arch = arch
        levels = len(arch["encoder"])
        if len(arch["decoder"]) != levels - 1:
            raise ValueError("the decoder needs one stage per encoder level but the deepest")
        if levels - 1 < NUM_OUTPUTS:
            raise ValueError(f"{NUM_OUTPUTS} outputs need at least {NUM_OUTPUTS + 1} levels")
        self.register_buffer("mean", torch.tensor(INPUT_MEAN).view(1, 3, 1, 1))
        self.register_buffer("std", torch.tensor(INPUT_STD).view(1, 3, 1, 1))

        enc_channels = []
        in_c = 3
        self.enc = nn.ModuleList()
        for specs in arch["encoder"]:
            stage, in_c = build_stage(specs, 4 * in_c)
            self.enc.append(stage)
            enc_channels.append(in_c)

        # decoder stage i works at level i + 1 (0-based list, level 1 = half resolution)
        dec_stages = [None] * (levels - 1)
        dec_channels = [None] * (levels - 1)
        below = enc_channels[-1]
        for i in reversed(range(levels - 1)):
            if below % 4:
                raise ValueError(f"level {i + 2} has {below} channels, not a multiple of 4 for the IDWT")
            dec_stages[i], dec_channels[i] = build_stage(arch["decoder"][i], below // 4 + enc_channels[i])
            below = dec_channels[i]
        self.dec = nn.ModuleList(dec_stages)
        k = arch["head_kernel"]
        # heads on levels 4..1 predict the Haar coefficients of the disparity one level up
        self.heads = nn.ModuleList(
            nn.Conv2d(dec_channels[i], 4, k, padding=k // 2) for i in range(NUM_OUTPUTS))
        self.multiple = multiple_of(arch)

    def forward(self, rgb: torch.Tensor):
        """rgb: [N, 3, H, W] in [0, 1], H and W multiples of self.multiple. Returns the
        disparity at 1/8, 1/4, 1/2 and full resolution, coarsest first, each [N, 1, h, w]."""
        if rgb.shape[-2] % self.multiple or rgb.shape[-1] % self.multiple:
            raise ValueError(f"input size {tuple(rgb.shape[-2:])} is not a multiple of {self.multiple}")
        x = (rgb - self.mean) / self.std
        skips = []
        for stage in self.enc:
            x = stage(haar_dwt(x))
            skips.append(x)
        y = skips[-1]
        outputs = []
        for i in reversed(range(len(self.dec))):
            y = self.dec[i](torch.cat([haar_idwt(y), skips[i]], dim=1))
            if i < NUM_OUTPUTS:
                outputs.append(haar_idwt(self.head(i, y)))
        return outputs

    def head(self, i: int, y: torch.Tensor) -> torch.Tensor:
        """Head i, in fp32 even under bf16 autocast (train_depth.py --bf16), so the
        disparity and every loss on it are fp32: bf16 keeps 8 significant bits (a
        disparity of 5 would move in steps of 1/32), and grid_sample, which reads it at
        the ranking loss's points, has no bf16 kernel on the CPU."""
        with torch.autocast(y.device.type, enabled=False):
            return self.heads[i](y.float())

    @torch.no_grad()
    def predict(self, rgb: torch.Tensor) -> torch.Tensor:
        """Inference: the full-resolution output only."""
        return self.forward(rgb)[-1]


def build(name: str) -> DepthNet:
    if name not in ARCHITECTURES:
        raise ValueError(f"unknown architecture {name!r} (known: {', '.join(ARCHITECTURES)})")
    return DepthNet(ARCHITECTURES[name])


def parameter_count(model: nn.Module) -> int:
    return sum(p.numel() for p in model.parameters())


def folded_parameter_count(model: nn.Module) -> int:
    """What the exported file holds: BN folded into its conv as a bias (mean/var dropped)."""
    total = 0
    for module in model.modules():
        if isinstance(module, nn.Conv2d):
            total += module.weight.numel()
            total += module.out_channels  # own bias, or the folded BN shift
    return total


def layer_table(name: str) -> str:
    """The markdown layer table of nets/ARCHITECTURE.md for one architecture."""
    net = build(name)
    rows = ["| stage | resolution | block | kind | in | expanded | out | kernel | SE | act | residual | parameters |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]

    def add(stage, level, specs, modules, in_c):
        for i, (spec, module) in enumerate(zip(specs, modules)):
            kind, out_c, exp_c, k, se, act = spec
            mb = kind == MB
            rows.append(f"| {stage} | 1/{2 ** level} | {i} | {'MobileNetV3' if mb else 'conv+BN'} | {in_c} | "
                        f"{exp_c if mb else '-'} | {out_c} | {k}x{k}{' dw' if mb else ''} | "
                        f"{se_reduced_channels(exp_c) if mb and se else '-'} | {act} | "
                        f"{'yes' if mb and in_c == out_c else 'no'} | {parameter_count(module)} |")
            in_c = out_c
        return in_c

    in_c, enc_c = 3, []
    for level, (specs, stage) in enumerate(zip(net.arch["encoder"], net.enc), start=1):
        rows.append(f"| DWT | 1/{2 ** level} | | Haar | {in_c} | | {4 * in_c} | 2x2 s2 | | | | 0 |")
        in_c = add(f"enc{level}", level, specs, stage, 4 * in_c)
        enc_c.append(in_c)
    below = in_c
    for level in reversed(range(1, len(net.dec) + 1)):
        rows.append(f"| IDWT + concat | 1/{2 ** level} | | Haar | {below} + skip {enc_c[level - 1]} | | "
                    f"{below // 4 + enc_c[level - 1]} | | | | | 0 |")
        below = add(f"dec{level}", level, net.arch["decoder"][level - 1], net.dec[level - 1],
                    below // 4 + enc_c[level - 1])
        if level <= NUM_OUTPUTS:
            k = net.arch["head_kernel"]
            rows.append(f"| head{level} + IDWT | 1/{2 ** (level - 1)} | | conv+bias, Haar | {below} | | 4 -> 1 | "
                        f"{k}x{k} | | none | | {parameter_count(net.heads[level - 1])} |")
    return "\n".join(rows)


if __name__ == "__main__":
    import sys
    if "--table" in sys.argv:
        for name in ARCHITECTURES:
            print(f"### {name}\n\n{layer_table(name)}\n")
    for name in ARCHITECTURES:
        net = build(name)
        trained = parameter_count(net)
        folded = folded_parameter_count(net)
        print(f"{name}: {trained} trainable parameters ({trained * 4 / 1e6:.2f} MB fp32), "
              f"{folded} after BN folding ({folded * 4 / 1e6:.2f} MB fp32)")

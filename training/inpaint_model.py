"""The MPI inpainting network: a small gated-convolution generator and a patch
discriminator (training only).

The generator follows the coarse network of Yu et al. 2018 ("Generative Image Inpainting
with Contextual Attention") with far fewer filters, and the gated convolutions of their
follow-up (Yu et al. 2019, "Free-Form Image Inpainting with Gated Convolution"): every
layer computes 2c channels and outputs ELU(feature) * sigmoid(gate), so the network
learns per pixel how much to trust what it sees, which is what a hole needs. Two strided
layers bring it to 1/4 resolution, dilated layers (rates 2, 4, 8) widen the receptive
field to about 150 px (the MPI margins are about 40 px wide), nearest up-sampling brings
it back, with one skip at 1/2 resolution and the input itself fed to the last stage so
the known border stays sharp.

Version 2 (the default): the network refines a classic fill instead of starting from
nothing. The caller fills every hole pixel with the fill named PREFILL first: "harmonic"
(membrane interpolation started from push-pull, inpaint/harmonic_fill.h) since v5,
"push-pull" before (training/inpaint_push_pull.py ports both from the C++);

    input  = [rgb, hole]                    rgb in [-1, 1], the prefill in the hole
    output = rgb + hole * tanh(...)         a learned residual, only inside the hole

and the last layer starts at zero, so an untrained network returns the prefill exactly
and training starts from its quality. Version 1 (residual=False, the first bundled
weights): input [rgb * (1 - hole), hole], output tanh(...).

"hole" is every pixel the network may not look at: at inference everything of the layer
that is not opaque (the margin to fill and the transparent rest), in training everything
outside the eroded layer mask. Only the pixels with ground truth are supervised.

The architecture is data (LAYERS): the exporter writes it into the weight file and the
C++ network (nets/inpaint_net.cpp) builds the same graph from it.
"""
from __future__ import annotations

import torch
import torch.nn as nn
import torch.nn.functional as F

IN_CHANNELS = 4  # rgb with the hole zeroed, hole mask
OUT_CHANNELS = 3
INPUT = -1  # a layer's source: the network input
NO_SKIP = -2  # a layer's skip: none
FEATURE_ACTIVATION = "elu"  # of the gated layers' feature half (alpha 1)
OUTPUT_ACTIVATION = "tanh"
MULTIPLE = 4  # input height and width must be multiples of this (two stride-2 layers)
PREFILL = "harmonic"  # what fills the hole before a version-2 (residual) network sees it

# One row per layer: (name, source, upsample, skip, out_channels, kernel, stride, dilation,
# gated). The layer reads layer `source`'s output (INPUT: the network input), up-sampled
# 2x nearest when `upsample`, then concatenated on channels with layer `skip`'s output
# (INPUT: the network input, NO_SKIP: nothing). Padding is "same": dilation*(kernel-1)/2
# on every side. Gated layers output ELU(f) * sigmoid(g) of their 2*out_channels; the
# last layer is a plain convolution with tanh.
LAYERS = [
    ("enc1", INPUT, 0, NO_SKIP, 16, 5, 2, 1, 1),   # 1/2
    ("enc2", 0, 0, NO_SKIP, 16, 3, 1, 1, 1),
    ("enc3", 1, 0, NO_SKIP, 32, 3, 2, 1, 1),       # 1/4
    ("mid1", 2, 0, NO_SKIP, 32, 3, 1, 1, 1),
    ("mid2", 3, 0, NO_SKIP, 32, 3, 1, 2, 1),
    ("mid3", 4, 0, NO_SKIP, 32, 3, 1, 4, 1),
    ("mid4", 5, 0, NO_SKIP, 32, 3, 1, 8, 1),
    ("mid5", 6, 0, NO_SKIP, 32, 3, 1, 1, 1),
    ("dec1", 7, 1, 1, 16, 3, 1, 1, 1),             # 1/2, skip from enc2
    ("dec2", 8, 0, NO_SKIP, 16, 3, 1, 1, 1),
    ("dec3", 9, 1, INPUT, 8, 3, 1, 1, 1),          # full, the input beside it
    ("out", 10, 0, NO_SKIP, OUT_CHANNELS, 3, 1, 1, 0),
]


def layer_in_channels(layers=LAYERS):
    """Input channels of every layer, derived from the graph."""
    outs, ins = [], []
    for name, source, _up, skip, out_c, _k, _s, _d, _g in layers:
        c = IN_CHANNELS if source == INPUT else outs[source]
        if skip == INPUT:
            c += IN_CHANNELS
        elif skip != NO_SKIP:
            c += outs[skip]
        ins.append(c)
        outs.append(out_c)
    return ins


def check_layers(layers=LAYERS):
    """The rules the C++ builder relies on; raises ValueError naming the broken layer."""
    scale = []  # of each layer's output, as a power of 1/2
    for i, (name, source, up, skip, _out_c, kernel, stride, _dil, gated) in enumerate(layers):
        if not (source == INPUT or 0 <= source < i):
            raise ValueError(f"layer {name}: source {source} is not an earlier layer")
        if not (skip in (INPUT, NO_SKIP) or 0 <= skip < i):
            raise ValueError(f"layer {name}: skip {skip} is not an earlier layer")
        if kernel % 2 == 0 or stride not in (1, 2):
            raise ValueError(f"layer {name}: kernel must be odd and stride 1 or 2")
        s = (0 if source == INPUT else scale[source]) - (1 if up else 0)
        if skip != NO_SKIP and (0 if skip == INPUT else scale[skip]) != s:
            raise ValueError(f"layer {name}: skip has another resolution")
        scale.append(s + (1 if stride == 2 else 0))
        if i == len(layers) - 1 and (gated or scale[-1] != 0):
            raise ValueError(f"layer {name}: the last layer must be plain, at full resolution")
    if 2 ** max(scale) > MULTIPLE:
        raise ValueError(f"the graph down-scales by more than {MULTIPLE}")


class GatedConv(nn.Module):
    """Convolution to 2c channels; ELU(first c) * sigmoid(last c)."""

    def __init__(self, in_c: int, out_c: int, kernel: int, stride: int, dilation: int):
        super().__init__()
        self.out_c = out_c
        self.conv = nn.Conv2d(in_c, 2 * out_c, kernel, stride, dilation * (kernel - 1) // 2, dilation)

    def forward(self, x):
        feature, gate = torch.split(self.conv(x), self.out_c, dim=1)
        return F.elu(feature) * torch.sigmoid(gate)


class InpaintGenerator(nn.Module):
    def __init__(self, layers=LAYERS, residual: bool = True):
        super().__init__()
        check_layers(layers)
        self.layers_spec = layers
        self.residual = residual
        self.convs = nn.ModuleList()
        for (name, _src, _up, _skip, out_c, kernel, stride, dil, gated), in_c in zip(
                layers, layer_in_channels(layers)):
            if gated:
                self.convs.append(GatedConv(in_c, out_c, kernel, stride, dil))
            else:
                self.convs.append(nn.Conv2d(in_c, out_c, kernel, stride, dil * (kernel - 1) // 2, dil))
        if residual:  # start as the identity on the pre-filled input: push-pull's quality
            nn.init.zeros_(self.convs[-1].weight)
            nn.init.zeros_(self.convs[-1].bias)

    @property
    def version(self) -> int:
        return 2 if self.residual else 1

    def forward(self, rgb: torch.Tensor, hole: torch.Tensor) -> torch.Tensor:
        """rgb: [N, 3, H, W] in [-1, 1] (residual: push-pull already in the hole);
        hole: [N, 1, H, W] in {0, 1}. Returns the prediction for every pixel, [N, 3, H, W]
        (the known pixels unchanged when residual)."""
        if rgb.shape[-2] % MULTIPLE or rgb.shape[-1] % MULTIPLE:
            raise ValueError(f"input size {tuple(rgb.shape[-2:])} is not a multiple of {MULTIPLE}")
        x = torch.cat([rgb if self.residual else rgb * (1.0 - hole), hole], dim=1)
        outs = []
        for (name, source, up, skip, *_rest), conv in zip(self.layers_spec, self.convs):
            y = x if source == INPUT else outs[source]
            if up:
                y = F.interpolate(y, scale_factor=2, mode="nearest")
            if skip != NO_SKIP:
                y = torch.cat([y, x if skip == INPUT else outs[skip]], dim=1)
            outs.append(conv(y))
        if self.residual:
            return rgb + hole * torch.tanh(outs[-1])
        return torch.tanh(outs[-1])


def composite(pred: torch.Tensor, rgb: torch.Tensor, hole: torch.Tensor) -> torch.Tensor:
    """The known pixels of rgb, the prediction in the hole."""
    return rgb * (1.0 - hole) + pred * hole


class PatchDiscriminator(nn.Module):
    """SN-PatchGAN (Yu et al. 2019): strided 5x5 convolutions with spectral normalisation;
    every output cell judges one patch of [rgb, hole]. Training only."""

    def __init__(self, channels=(32, 64, 64, 64)):
        super().__init__()
        layers, in_c = [], IN_CHANNELS
        for c in channels:
            layers += [nn.utils.spectral_norm(nn.Conv2d(in_c, c, 5, 2, 2)), nn.LeakyReLU(0.2)]
            in_c = c
        layers.append(nn.utils.spectral_norm(nn.Conv2d(in_c, 1, 3, 1, 1)))
        self.net = nn.Sequential(*layers)

    def forward(self, rgb: torch.Tensor, hole: torch.Tensor) -> torch.Tensor:
        return self.net(torch.cat([rgb, hole], dim=1))


def parameter_count(model: nn.Module) -> int:
    return sum(p.numel() for p in model.parameters())


def macs_per_pixel(layers=LAYERS) -> float:
    """Multiply-adds per full-resolution input pixel (what the C++ side computes)."""
    total, scale = 0.0, []
    for (name, source, up, _skip, out_c, kernel, stride, _dil, gated), in_c in zip(
            layers, layer_in_channels(layers)):
        s = (0 if source == INPUT else scale[source]) - (1 if up else 0) + (1 if stride == 2 else 0)
        scale.append(s)
        total += kernel * kernel * in_c * out_c * (2 if gated else 1) / 4 ** s
    return total


if __name__ == "__main__":
    g = InpaintGenerator()
    print(f"generator: {parameter_count(g)} parameters, {macs_per_pixel() / 1e3:.1f} kMAC per pixel")
    print(f"discriminator: {parameter_count(PatchDiscriminator())} parameters")

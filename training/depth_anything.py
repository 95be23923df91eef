"""Depth Anything V2 (Yang et al. 2024) in PyTorch: our own twin of the reference model.

The teacher of the paper's distillation (`ampi distill`). A DINOv2 vision transformer encodes
the image as 14x14 patches; a DPT head turns the tokens of four of its blocks into a
relative inverse-depth map (larger = nearer) at the input resolution:

    x      = (rgb - mean) / std                       H x W x 3, H and W multiples of 14
    t_0    = [cls ; patch_embed(x)] + pos(H/14, W/14)  1 + (H/14)(W/14) tokens of `dim`
    t_i    = block_i(t_{i-1})                          i = 1..depth (pre-norm, LayerScale)
    f_k    = norm(t_{layers[k]})[1:]                   four token maps, class token dropped
    r_k    = resize_k(project_k(f_k))                  1/14 x (4, 2, 1, 1/2) of the grid
    out    = relu(head(fuse(r_1 .. r_4)))              H x W

Every module and parameter is named as in the official checkpoints
(`depth_anything_v2_vits.pth` and its Base and Large siblings), so their state dicts load
into `DepthAnythingV2` strictly. The code is written from the published architecture and
checked against the official implementation on random weights by
`check_depth_anything.py` (record: DEPTH_ANYTHING.md); none of it is copied.

The reference preprocessing is `preprocess` and the whole reference `infer_image` is
`infer`: RGB in [0, 1], ImageNet mean and std, a cubic resize keeping the aspect ratio
so that the short side reaches the working size (518) and both sides are multiples of 14,
and the output resized back bilinearly (align_corners=True) to the photo's size.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

IMAGENET_MEAN = (0.485, 0.456, 0.406)
IMAGENET_STD = (0.229, 0.224, 0.225)
WORKING_SIZE = 518  # the reference `infer_image`'s default input_size
PATCH = 14


@dataclass(frozen=True)
class Config:
    """The dimensions of one Depth Anything V2 model: ViT encoder, then DPT head."""
    embed_dim: int
    depth: int  # transformer blocks
    heads: int
    layers: tuple  # the four blocks (0-based) whose outputs feed the DPT head
    features: int  # width of the DPT fusion path
    out_channels: tuple  # widths of the four DPT projections
    patch_size: int = PATCH
    mlp_ratio: int = 4
    pos_grid: int = 37  # the position embedding's patch grid: the 518x518 pretraining size / 14
    pos_offset: float = 0.1  # DINOv2's offset added to the target grid before bicubic scaling
    head_hidden: int = 32  # channels of the last hidden convolution of the output head
    norm_eps: float = 1e-6

    @property
    def mlp_hidden(self) -> int:
        return self.embed_dim * self.mlp_ratio


# The official sizes (Small, Base, Large); the names are the checkpoints' suffixes.
VARIANTS = {
    "vits": Config(384, 12, 6, (2, 5, 8, 11), 64, (48, 96, 192, 384)),
    "vitb": Config(768, 12, 12, (2, 5, 8, 11), 128, (96, 192, 384, 768)),
    "vitl": Config(1024, 24, 16, (4, 11, 17, 23), 256, (256, 512, 1024, 1024)),
}

# A configuration small enough for unit tests and committed fixtures (not a real model).
TINY = Config(embed_dim=16, depth=5, heads=2, layers=(0, 2, 3, 4), features=8, out_channels=(4, 8, 12, 16),
              pos_grid=4, head_hidden=8)


# ---- the ViT encoder (DINOv2) -------------------------------------------------------------


class PatchEmbed(nn.Module):
    """Non-overlapping patch x patch convolution: image -> tokens [B, N, dim], row-major."""

    def __init__(self, cfg: Config):
        super().__init__()
        self.proj = nn.Conv2d(3, cfg.embed_dim, cfg.patch_size, stride=cfg.patch_size)

    def forward(self, x):
        return self.proj(x).flatten(2).transpose(1, 2)


class LayerScale(nn.Module):
    """Per-channel scale of a residual branch (folded into the weights at import)."""

    def __init__(self, dim: int):
        super().__init__()
        self.gamma = nn.Parameter(torch.ones(dim))

    def forward(self, x):
        return x * self.gamma


class Attention(nn.Module):
    """Multi-head self-attention: one qkv projection, softmax(q k^T / sqrt(d)) v, output
    projection. q is scaled before the product, as the reference does."""

    def __init__(self, cfg: Config):
        super().__init__()
        self.heads = cfg.heads
        self.scale = (cfg.embed_dim // cfg.heads) ** -0.5
        self.qkv = nn.Linear(cfg.embed_dim, 3 * cfg.embed_dim)
        self.proj = nn.Linear(cfg.embed_dim, cfg.embed_dim)

    def forward(self, x):
        b, n, c = x.shape
        q, k, v = self.qkv(x).reshape(b, n, 3, self.heads, c // self.heads).permute(2, 0, 3, 1, 4)
        weights = ((q * self.scale) @ k.transpose(-2, -1)).softmax(dim=-1)
        return self.proj((weights @ v).transpose(1, 2).reshape(b, n, c))


class Mlp(nn.Module):
    """fc1, exact (erf) GELU, fc2."""

    def __init__(self, cfg: Config):
        super().__init__()
        self.fc1 = nn.Linear(cfg.embed_dim, cfg.mlp_hidden)
        self.fc2 = nn.Linear(cfg.mlp_hidden, cfg.embed_dim)

    def forward(self, x):
        return self.fc2(F.gelu(self.fc1(x)))


class Block(nn.Module):
    """Pre-norm transformer block with LayerScale on both residual branches."""

    def __init__(self, cfg: Config):
        super().__init__()
        self.norm1 = nn.LayerNorm(cfg.embed_dim, eps=cfg.norm_eps)
        self.attn = Attention(cfg)
        self.ls1 = LayerScale(cfg.embed_dim)
        self.norm2 = nn.LayerNorm(cfg.embed_dim, eps=cfg.norm_eps)
        self.mlp = Mlp(cfg)
        self.ls2 = LayerScale(cfg.embed_dim)

    def forward(self, x):
        x = x + self.ls1(self.attn(self.norm1(x)))
        return x + self.ls2(self.mlp(self.norm2(x)))


def interpolate_pos_embed(pos_embed: torch.Tensor, rows: int, cols: int, offset: float) -> torch.Tensor:
    """The position embedding [1, 1 + G*G, dim] for a rows x cols patch grid.

    As DINOv2 does it: the class token's entry is kept; the G x G patch grid is resized
    bicubically (a = -0.75, align_corners=False, no antialias) with the *scale factors*
    (rows + offset) / G and (cols + offset) / G, so the output is rows x cols but the
    sample positions follow the offset scale, src = (i + 0.5) * G / (rows + offset) - 0.5.
    A grid equal to G x G is returned unchanged (no resampling at all)."""
    grid = math.isqrt(int(pos_embed.shape[1]) - 1)  # int(): a plain number under ONNX tracing too
    if rows == grid and cols == grid:
        return pos_embed
    dim = pos_embed.shape[-1]
    patches = pos_embed[:, 1:].reshape(1, grid, grid, dim).permute(0, 3, 1, 2)
    scale = ((rows + offset) / grid, (cols + offset) / grid)
    patches = F.interpolate(patches, scale_factor=scale, mode="bicubic", align_corners=False)
    if patches.shape[-2:] != (rows, cols):
        raise ValueError(f"position embedding resized to {tuple(patches.shape[-2:])}, not {(rows, cols)}")
    patches = patches.permute(0, 2, 3, 1).reshape(1, rows * cols, dim)
    return torch.cat((pos_embed[:, :1], patches), dim=1)


def cubic_resize_matrix(n_out: int, n_in: int, src_per_dst: float) -> np.ndarray:
    """[n_out, n_in] matrix of one axis of PyTorch's bicubic resize (a = -0.75,
    align_corners=False, indices clamped to the edge): out = M @ in. `src_per_dst` is the
    step between sample positions (1 / scale factor). Written out so that the C++ side has
    the exact formula; tests check it against `interpolate_pos_embed`."""
    a = -0.75

    def near(t):  # |t| <= 1
        return ((a + 2) * t - (a + 3)) * t * t + 1

    def far(t):  # 1 < |t| < 2
        return ((a * t - 5 * a) * t + 8 * a) * t - 4 * a

    m = np.zeros((n_out, n_in))
    for i in range(n_out):
        src = (i + 0.5) * src_per_dst - 0.5
        base = int(np.floor(src))
        t = src - base
        for k, w in zip(range(base - 1, base + 3), (far(t + 1), near(t), near(1 - t), far(2 - t))):
            m[i, min(max(k, 0), n_in - 1)] += w
    return m


class VisionTransformer(nn.Module):
    """The DINOv2 encoder (`pretrained.*` in the checkpoints)."""

    def __init__(self, cfg: Config):
        super().__init__()
        self.cfg = cfg
        self.patch_embed = PatchEmbed(cfg)
        self.cls_token = nn.Parameter(torch.zeros(1, 1, cfg.embed_dim))
        self.pos_embed = nn.Parameter(torch.zeros(1, 1 + cfg.pos_grid ** 2, cfg.embed_dim))
        self.mask_token = nn.Parameter(torch.zeros(1, cfg.embed_dim))  # pretraining only; kept for the keys
        self.blocks = nn.ModuleList(Block(cfg) for _ in range(cfg.depth))
        self.norm = nn.LayerNorm(cfg.embed_dim, eps=cfg.norm_eps)

    def tokens(self, x):
        """Class token and patch tokens with their position embedding, [B, 1 + N, dim]."""
        rows, cols = x.shape[-2] // self.cfg.patch_size, x.shape[-1] // self.cfg.patch_size
        t = self.patch_embed(x)
        t = torch.cat((self.cls_token.expand(t.shape[0], -1, -1), t), dim=1)
        return t + interpolate_pos_embed(self.pos_embed, rows, cols, self.cfg.pos_offset)

    def intermediate(self, x):
        """The final-norm'd patch tokens [B, N, dim] after each block of `cfg.layers`."""
        t, taken = self.tokens(x), []
        for i, block in enumerate(self.blocks[:max(self.cfg.layers) + 1]):
            t = block(t)
            if i in self.cfg.layers:
                taken.append(self.norm(t)[:, 1:])
        return taken


# ---- the DPT head ---------------------------------------------------------------------------


def conv3x3(c_in: int, c_out: int, bias: bool = True, stride: int = 1) -> nn.Conv2d:
    return nn.Conv2d(c_in, c_out, 3, stride=stride, padding=1, bias=bias)


def upsample(x, size):
    """Bilinear resize with align_corners=True (every resize of the DPT head)."""
    return F.interpolate(x, size=size, mode="bilinear", align_corners=True)


class ResidualConvUnit(nn.Module):
    """x + conv2(relu(conv1(relu(x)))), 3x3 convolutions with bias."""

    def __init__(self, features: int):
        super().__init__()
        self.conv1 = conv3x3(features, features)
        self.conv2 = conv3x3(features, features)

    def forward(self, x):
        return x + self.conv2(F.relu(self.conv1(F.relu(x))))


class FusionBlock(nn.Module):
    """DPT's feature fusion: add the refined skip, refine, upsample, 1x1 projection.

    The coarsest block has no skip and so never uses resConfUnit1; the checkpoints hold
    its weights anyway, so it exists here too."""

    def __init__(self, features: int):
        super().__init__()
        self.resConfUnit1 = ResidualConvUnit(features)  # noqa: N815 (the checkpoint's name)
        self.resConfUnit2 = ResidualConvUnit(features)  # noqa: N815
        self.out_conv = nn.Conv2d(features, features, 1)

    def forward(self, x, skip=None, size=None):
        if skip is not None:
            x = x + self.resConfUnit1(skip)
        x = self.resConfUnit2(x)
        size = size if size is not None else (2 * x.shape[-2], 2 * x.shape[-1])
        return self.out_conv(upsample(x, size))


def resize_layer(k: int, channels: int) -> nn.Module:
    """Brings projection k to its scale: x4 and x2 by transposed convolutions (kernel =
    stride, no overlap), x1 unchanged, /2 by a strided 3x3 convolution."""
    if k == 0:
        return nn.ConvTranspose2d(channels, channels, 4, stride=4)
    if k == 1:
        return nn.ConvTranspose2d(channels, channels, 2, stride=2)
    if k == 2:
        return nn.Identity()
    return conv3x3(channels, channels, stride=2)


class Scratch(nn.Module):
    """The DPT head's fusion path and output head (`depth_head.scratch.*`)."""

    def __init__(self, cfg: Config):
        super().__init__()
        f = cfg.features
        for k, c in enumerate(cfg.out_channels, start=1):
            setattr(self, f"layer{k}_rn", conv3x3(c, f, bias=False))
        for k in range(1, 5):
            setattr(self, f"refinenet{k}", FusionBlock(f))
        self.output_conv1 = conv3x3(f, f // 2)
        self.output_conv2 = nn.Sequential(conv3x3(f // 2, cfg.head_hidden), nn.ReLU(),
                                          nn.Conv2d(cfg.head_hidden, 1, 1), nn.ReLU())


class DPTHead(nn.Module):
    """Token maps of four blocks -> one-channel map at the input resolution."""

    def __init__(self, cfg: Config):
        super().__init__()
        self.cfg = cfg
        self.projects = nn.ModuleList(nn.Conv2d(cfg.embed_dim, c, 1) for c in cfg.out_channels)
        self.resize_layers = nn.ModuleList(resize_layer(k, c) for k, c in enumerate(cfg.out_channels))
        self.scratch = Scratch(cfg)

    def pyramid(self, tokens, rows: int, cols: int):
        """The four maps at 4x, 2x, 1x and 1/2x the patch grid, `features` wide each."""
        s = self.scratch
        maps = []
        for k, t in enumerate(tokens):
            x = t.transpose(1, 2).reshape(t.shape[0], t.shape[2], rows, cols)
            x = self.resize_layers[k](self.projects[k](x))
            maps.append(getattr(s, f"layer{k + 1}_rn")(x))
        return maps

    def forward(self, tokens, rows: int, cols: int):
        s = self.scratch
        l1, l2, l3, l4 = self.pyramid(tokens, rows, cols)
        x = s.refinenet4(l4, size=l3.shape[-2:])
        x = s.refinenet3(x, l3, size=l2.shape[-2:])
        x = s.refinenet2(x, l2, size=l1.shape[-2:])
        x = s.refinenet1(x, l1)
        x = upsample(s.output_conv1(x), (rows * self.cfg.patch_size, cols * self.cfg.patch_size))
        return s.output_conv2(x)


class DepthAnythingV2(nn.Module):
    """The whole model: normalised image [B, 3, H, W] (multiples of 14) -> [B, H, W]."""

    def __init__(self, cfg: Config):
        super().__init__()
        self.cfg = cfg
        self.pretrained = VisionTransformer(cfg)
        self.depth_head = DPTHead(cfg)

    def forward(self, x):
        p = self.cfg.patch_size
        if x.shape[-2] % p or x.shape[-1] % p:
            raise ValueError(f"input {tuple(x.shape[-2:])} is not a multiple of the patch size {p}")
        rows, cols = x.shape[-2] // p, x.shape[-1] // p
        out = self.depth_head(self.pretrained.intermediate(x), rows, cols)
        return F.relu(out).squeeze(1)


def build(variant_or_cfg) -> DepthAnythingV2:
    """The model of a variant name ("vits", "vitb", "vitl") or a Config, in eval mode."""
    cfg = VARIANTS[variant_or_cfg] if isinstance(variant_or_cfg, str) else variant_or_cfg
    return DepthAnythingV2(cfg).eval()


# ---- LayerScale folding -------------------------------------------------------------------


def fold_layer_scale(state: dict) -> dict:
    """A state dict computing the same function with every LayerScale folded into the
    linear layer before it (ls1 into attn.proj, ls2 into mlp.fc2: W' = diag(g) W,
    b' = g * b, in float64) and the gammas set to 1, so a runtime needs no LayerScale op."""
    out = dict(state)
    for key in [k for k in state if k.endswith((".ls1.gamma", ".ls2.gamma"))]:
        block = key[:-len(".ls1.gamma")]
        layer = f"{block}.attn.proj" if key.endswith(".ls1.gamma") else f"{block}.mlp.fc2"
        g = state[key].double()
        out[f"{layer}.weight"] = (state[f"{layer}.weight"].double() * g[:, None]).to(state[f"{layer}.weight"].dtype)
        out[f"{layer}.bias"] = (state[f"{layer}.bias"].double() * g).to(state[f"{layer}.bias"].dtype)
        out[key] = torch.ones_like(state[key])
    return out


# ---- random weights for checks and fixtures ------------------------------------------------


def randomise_(model: nn.Module, seed: int, last_bias: float = 0.5) -> nn.Module:
    """Gives every parameter of a model with these key names (the twin or the official
    model) seeded random values that exercise every path: unit-variance linear layers (so
    attention is not uniform), LayerNorm and LayerScale away from 1, non-zero biases and
    class/position tokens. The last convolution's bias is raised so that the final ReLU
    does not zero most pixels. The same seed gives the same values to both models."""
    g = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for name, p in sorted(model.named_parameters()):
            p.copy_(_random_value(name, p.shape, g))
        model.depth_head.scratch.output_conv2[2].bias.add_(last_bias)
    return model


def _random_value(name: str, shape, g: torch.Generator) -> torch.Tensor:
    noise = torch.randn(shape, generator=g)
    if name.endswith("gamma"):
        return 0.5 + torch.rand(shape, generator=g)
    if ".norm" in name:  # LayerNorms: blocks' norm1, norm2 and the final pretrained.norm
        return 1.0 + 0.2 * noise if name.endswith("weight") else 0.1 * noise
    if name.endswith("bias"):
        return 0.05 * noise
    if name.endswith(("cls_token", "pos_embed", "mask_token")):
        return 0.5 * noise
    fan_in = int(np.prod(shape[1:])) if len(shape) > 1 else 1
    if ".resize_layers.0." in name or ".resize_layers.1." in name:
        fan_in = shape[0]  # ConvTranspose2d weights are [in, out, kh, kw]
    return noise / fan_in ** 0.5


# ---- the reference preprocessing ------------------------------------------------------------


def _round_half_even(x: float) -> int:
    return int(round(x))  # Python rounds halves to even, as numpy's np.round does


def working_shape(height: int, width: int, size: int = WORKING_SIZE, multiple: int = PATCH):
    """(rows, cols) the reference resizes a height x width photo to: the aspect ratio
    kept, scaled so that the *shorter* side reaches `size` ("lower_bound"), each side then
    rounded to the nearest multiple (halves to even) and raised to the next multiple if
    that fell below `size`."""
    scale = max(size / height, size / width)

    def side(x: float) -> int:
        y = _round_half_even(x / multiple) * multiple
        return y if y >= size else int(np.ceil(x / multiple)) * multiple

    return side(scale * height), side(scale * width)


def to_unit_rgb(image: np.ndarray) -> np.ndarray:
    """H x W x 3 RGB as float32 in [0, 1] (uint8 divided by 255; floats taken as they are)."""
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an H x W x 3 RGB image, got shape {image.shape}")
    if image.dtype == np.uint8:
        return image.astype(np.float32) / 255.0
    return image.astype(np.float32)


def preprocess(image: np.ndarray, size: int = WORKING_SIZE, multiple: int = PATCH) -> torch.Tensor:
    """The network input [1, 3, rows, cols] of an RGB photo: resized to `working_shape`
    by bicubic interpolation (a = -0.75, align_corners=False, edge-clamped, which is what
    OpenCV's INTER_CUBIC computes), then normalised with the ImageNet mean and std."""
    rgb = torch.from_numpy(to_unit_rgb(image)).permute(2, 0, 1)[None]
    rows, cols = working_shape(rgb.shape[-2], rgb.shape[-1], size, multiple)
    if (rows, cols) != tuple(rgb.shape[-2:]):
        rgb = F.interpolate(rgb, size=(rows, cols), mode="bicubic", align_corners=False)
    mean = torch.tensor(IMAGENET_MEAN).view(1, 3, 1, 1)
    std = torch.tensor(IMAGENET_STD).view(1, 3, 1, 1)
    return (rgb - mean) / std


@torch.no_grad()
def infer(model: DepthAnythingV2, image: np.ndarray, size: int = WORKING_SIZE) -> np.ndarray:
    """Relative inverse depth [H, W] of an RGB photo (uint8, or float in [0, 1]), as the
    reference `infer_image` computes it: preprocess, run, bilinear resize back with
    align_corners=True."""
    height, width = image.shape[:2]
    out = model(preprocess(image, size, model.cfg.patch_size))
    return upsample(out[:, None], (height, width))[0, 0].numpy()


def tiny(**changes) -> Config:
    """TINY with some fields changed (tests)."""
    return replace(TINY, **changes)

"""Converts an official Depth Anything V2 checkpoint to ampi's weight file (.ampw).

    /usr/bin/python3 training/import_depth_anything.py depth_anything_v2_vits.pth weights/dav2_vits.ampw

The checkpoint (a plain PyTorch state dict, e.g. `depth_anything_v2_vits.pth` from
https://huggingface.co/depth-anything/Depth-Anything-V2-Small) is read on the CPU with
`weights_only=True`, its size (vits, vitb, vitl) is recognised from its tensor shapes, and
it is loaded strictly into our twin (depth_anything.py), so every tensor is checked by
name and shape. A wrong, truncated or foreign file gets one line on stderr naming the file
and the problem, exit code 1, and no output file.

What the file holds (the C++ builder reads it; training/DEPTH_ANYTHING.md has the table):
  metadata  arch = "ampi.depth.dav2-vit-dpt", depth.variant (vits | vitb | vitl), the
            dimensions (dav2.*: embed dim, blocks, heads, MLP width, patch size, position
            grid and offset, LayerNorm eps, the four intermediate blocks, DPT features,
            projection widths, output head width), the reference preprocessing (depth.*:
            mean, std, multiple 14, working size 518, resize rule and interpolations),
            and provenance (source.*, import.*).
  tensors   the checkpoint's names, f32, with LayerScale folded into the linear layer
            before it (attn.proj, mlp.fc2) so no `*.ls1.gamma` / `*.ls2.gamma` remain, and
            without the two tensors inference never reads (pretrained.mask_token and
            refinenet4.resConfUnit1, the coarsest fusion block having no skip input).
            Layouts (LAYOUT below): convolutions OHWI [out][kh][kw][in] like every ampi
            network; transposed convolutions [kh][kw][out][in], i.e. kh*kw*out rows of a
            GEMM over the input channels; linear layers [out][in] as PyTorch has them
            (qkv rows: q, then k, then v, each head after head); cls_token [dim];
            pos_embed [1 + G*G][dim] (row 0 the class token's, then the G x G grid row-major).
"""
from __future__ import annotations

import argparse
import hashlib
import inspect
import sys
from pathlib import Path

import numpy as np
import torch

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "weights_format"))
import depth_anything as dav2  # noqa: E402
from ampw import AmpwError, read_ampw, write_ampw  # noqa: E402
from export_depth import git_commit  # noqa: E402

ARCH_NAME = "ampi.depth.dav2-vit-dpt"
FORMAT_VERSION = 1
PATCH_KEY = "pretrained.patch_embed.proj.weight"
TRANSPOSED = ("depth_head.resize_layers.0.weight", "depth_head.resize_layers.1.weight")
UNUSED_PREFIXES = ("pretrained.mask_token", "depth_head.scratch.refinenet4.resConfUnit1.")
LICENCES = {"vits": "Apache-2.0", "vitb": "CC-BY-NC-4.0", "vitl": "CC-BY-NC-4.0"}
MODEL_PAGES = {"vits": "https://huggingface.co/depth-anything/Depth-Anything-V2-Small",
               "vitb": "https://huggingface.co/depth-anything/Depth-Anything-V2-Base",
               "vitl": "https://huggingface.co/depth-anything/Depth-Anything-V2-Large"}
LAYOUT = ("conv OHWI [out][kh][kw][in]; conv-transpose [kh][kw][out][in]; linear [out][in]; "
          "cls_token [dim]; pos_embed [1 + grid*grid][dim]; LayerScale folded into attn.proj and mlp.fc2")


class CheckpointError(ValueError):
    """A checkpoint that is not a usable Depth Anything V2 state dict (one-line message)."""


# ---- reading and recognising a checkpoint ------------------------------------------------


def _first_line(error: BaseException) -> str:
    text = str(error).strip().splitlines()
    return f"{type(error).__name__}: {text[0]}" if text else type(error).__name__


def _load_error(error: BaseException) -> str:
    """torch.load's complaint in a few words (its weights-only refusal is a paragraph)."""
    text = str(error)
    if "Weights only load failed" in text:
        detail = text.split("WeightsUnpickler error:")[-1].strip().splitlines()[0]
        return f"not a plain file of tensors ({detail})"
    return _first_line(error)


def load_state(path: str) -> dict:
    """The checkpoint's state dict (name -> tensor), read on the CPU without running any
    pickled code where this torch allows it."""
    if "metric" in Path(path).name.lower():
        raise CheckpointError(f"{path}: looks like a metric-depth checkpoint; its head ends in a sigmoid "
                              "times a maximum depth, which this importer does not build (use the relative "
                              "depth_anything_v2_vit{s,b,l}.pth)")
    try:
        with open(path, "rb") as f:
            head = f.read(4)
    except OSError as e:
        raise CheckpointError(f"{path}: cannot read: {e.strerror or e}") from None
    if not head:
        raise CheckpointError(f"{path}: empty file")
    if head == b"AMPW":
        raise CheckpointError(f"{path}: already an ampi weight file (.ampw), not a PyTorch checkpoint")
    kwargs = {"map_location": "cpu"}
    if "weights_only" in inspect.signature(torch.load).parameters:
        kwargs["weights_only"] = True
    try:
        obj = torch.load(path, **kwargs)
    except Exception as e:  # noqa: BLE001 (torch raises many kinds for a damaged file)
        raise CheckpointError(f"{path}: not a readable PyTorch checkpoint (truncated or another format?): "
                              f"{_load_error(e)}") from None
    return _unwrap(path, obj)


def _unwrap(path: str, obj) -> dict:
    """The state dict inside `obj`: obj itself, or its 'model' / 'state_dict' entry."""
    if isinstance(obj, dict) and not any(torch.is_tensor(v) for v in obj.values()):
        for key in ("model", "state_dict"):
            if isinstance(obj.get(key), dict):
                obj = obj[key]
                break
    if not isinstance(obj, dict):
        raise CheckpointError(f"{path}: holds a {type(obj).__name__}, not a state dict")
    if not obj:
        raise CheckpointError(f"{path}: holds an empty dict, not a state dict")
    return obj


def detect_variant(path: str, state: dict) -> str:
    """vits, vitb or vitl, from the patch embedding's width."""
    weight = state.get(PATCH_KEY)
    if not torch.is_tensor(weight) or weight.dim() != 4:
        some = ", ".join(repr(str(k)) for k in list(state)[:2])
        raise CheckpointError(f"{path}: not a Depth Anything V2 checkpoint (no 4-D tensor {PATCH_KEY!r}; "
                              f"its keys begin {some})")
    dim = int(weight.shape[0])
    by_dim = {cfg.embed_dim: name for name, cfg in dav2.VARIANTS.items()}
    if dim not in by_dim:
        sizes = ", ".join(f"{n} {c.embed_dim}" for n, c in dav2.VARIANTS.items())
        extra = " (ViT-G, not supported)" if dim == 1536 else ""
        raise CheckpointError(f"{path}: embed dim {dim}{extra} is none of the Depth Anything V2 sizes ({sizes})")
    return by_dim[dim]


def check_against(path: str, variant: str, state: dict, model: torch.nn.Module):
    """Every tensor the model has is present, of its shape, floating point and finite,
    and nothing else is: a precise one-line reason instead of load_state_dict's list."""
    expected = model.state_dict()
    missing = [k for k in expected if k not in state]
    extra = [k for k in state if k not in expected]
    for what, keys in (("is missing", missing), ("has unexpected", extra)):
        if keys:
            raise CheckpointError(f"{path}: {variant} checkpoint {what} {len(keys)} tensor(s), "
                                  f"first {keys[0]!r} (truncated, or another model?)")
    for key, want in expected.items():
        got = state[key]
        if not torch.is_tensor(got) or not got.is_floating_point():
            raise CheckpointError(f"{path}: {key!r} is not a floating-point tensor")
        if tuple(got.shape) != tuple(want.shape):
            raise CheckpointError(f"{path}: {key!r} has shape {tuple(got.shape)}, {variant} needs "
                                  f"{tuple(want.shape)}")
        if not torch.isfinite(got).all():
            raise CheckpointError(f"{path}: {key!r} holds non-finite values")


def load_checkpoint(path: str):
    """(variant, twin with the checkpoint's weights in eval mode, state dict as float32)."""
    state = load_state(path)
    variant = detect_variant(path, state)
    model = dav2.build(variant)
    check_against(path, variant, state, model)
    state = {k: v.float() for k, v in state.items()}
    model.load_state_dict(state, strict=True)
    return variant, model.eval(), state


# ---- the weight file ------------------------------------------------------------------------


def to_file_layout(name: str, t: torch.Tensor) -> np.ndarray:
    """One tensor in the layout the C++ side reads (module docstring)."""
    t = t.detach().float()
    if name in TRANSPOSED:
        t = t.permute(2, 3, 1, 0)  # [in][out][kh][kw] -> [kh][kw][out][in]
    elif t.dim() == 4:
        t = t.permute(0, 2, 3, 1)  # OIHW -> OHWI
    elif name.endswith(("cls_token", "pos_embed")):
        t = t.reshape(-1, t.shape[-1]) if name.endswith("pos_embed") else t.reshape(-1)
    return np.ascontiguousarray(t.numpy())


def from_file_layout(name: str, a: np.ndarray, like: torch.Tensor) -> torch.Tensor:
    """The inverse of to_file_layout, to the shape of the model's parameter `like`."""
    t = torch.from_numpy(np.array(a, dtype=np.float32))
    if name in TRANSPOSED:
        t = t.permute(3, 2, 0, 1)
    elif t.dim() == 4:
        t = t.permute(0, 3, 1, 2)
    return t.reshape(like.shape).contiguous()


def is_unused(name: str) -> bool:
    return name.startswith(UNUSED_PREFIXES)


def metadata(cfg: dav2.Config, variant: str, working_size: int = dav2.WORKING_SIZE) -> dict:
    """The architecture and the reference preprocessing, as the C++ builder reads them."""
    return {
        "arch": ARCH_NAME,
        "depth.format_version": FORMAT_VERSION,
        "depth.variant": variant,
        "depth.input": "RGB in [0, 1], x' = (x - mean) / std per channel; H, W multiples of depth.multiple",
        "depth.input_mean": [float(v) for v in dav2.IMAGENET_MEAN],
        "depth.input_std": [float(v) for v in dav2.IMAGENET_STD],
        "depth.multiple": cfg.patch_size,
        "depth.working_size": int(working_size),
        "depth.resize": "keep aspect ratio, shorter side to the working size, each side rounded to the nearest "
                        "multiple (halves to even), raised to the next multiple if below the working size",
        "depth.resize_interpolation": "cubic",  # OpenCV INTER_CUBIC = bicubic a=-0.75, half-pixel centres
        "depth.output_interpolation": "bilinear_align_corners",
        "depth.output": "relative inverse depth (larger = nearer), >= 0 (final ReLU), scale and shift free",
        "dav2.embed_dim": cfg.embed_dim,
        "dav2.depth": cfg.depth,
        "dav2.heads": cfg.heads,
        "dav2.mlp_hidden": cfg.mlp_hidden,
        "dav2.patch_size": cfg.patch_size,
        "dav2.pos_grid": cfg.pos_grid,
        "dav2.pos_offset": float(cfg.pos_offset),
        "dav2.norm_eps": float(cfg.norm_eps),
        "dav2.layers": [int(i) for i in cfg.layers],
        "dav2.features": cfg.features,
        "dav2.out_channels": [int(c) for c in cfg.out_channels],
        "dav2.head_hidden": cfg.head_hidden,
        "dav2.layer_scale": "folded: attn.proj and mlp.fc2 weights and biases multiplied by ls1/ls2 gamma",
        "dav2.layout": LAYOUT,
    }


def ampw_contents(state: dict, cfg: dav2.Config, variant: str, provenance: dict,
                  working_size: int = dav2.WORKING_SIZE):
    """(tensors, metadata) of a weight file for a state dict of the twin's keys."""
    folded = dav2.fold_layer_scale({k: v.detach().float() for k, v in state.items()})
    tensors = {k: to_file_layout(k, v) for k, v in folded.items()
               if not is_unused(k) and not k.endswith(("ls1.gamma", "ls2.gamma"))}
    meta = metadata(cfg, variant, working_size)
    meta["depth.parameters"] = int(sum(a.size for a in tensors.values()))
    meta.update(provenance)
    return tensors, meta


def source_provenance(path: str, variant: str) -> dict:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            digest.update(chunk)
    return {"source.file": Path(path).name, "source.sha256": digest.hexdigest(),
            "source.bytes": Path(path).stat().st_size, "source.model": f"Depth Anything V2 ({variant})",
            "source.page": MODEL_PAGES.get(variant, "unknown"), "source.licence": LICENCES.get(variant, "unknown"),
            "import.tool": "training/import_depth_anything.py", "import.commit": git_commit(),
            "import.torch": torch.__version__}


def convert(checkpoint: str, output: str) -> dict:
    """Reads, checks and writes; returns the metadata written."""
    variant, model, state = load_checkpoint(checkpoint)
    tensors, meta = ampw_contents(state, model.cfg, variant, source_provenance(checkpoint, variant))
    try:
        write_ampw(output, tensors, meta)
    except OSError as e:
        raise CheckpointError(f"{output}: cannot write: {e.strerror or e}") from None
    return meta


# ---- back from the weight file --------------------------------------------------------------


def config_from_metadata(meta: dict) -> dav2.Config:
    dim = int(meta["dav2.embed_dim"])
    return dav2.Config(embed_dim=dim, depth=int(meta["dav2.depth"]), heads=int(meta["dav2.heads"]),
                       layers=tuple(int(i) for i in meta["dav2.layers"]), features=int(meta["dav2.features"]),
                       out_channels=tuple(int(c) for c in meta["dav2.out_channels"]),
                       patch_size=int(meta["dav2.patch_size"]), mlp_ratio=int(meta["dav2.mlp_hidden"]) // dim,
                       pos_grid=int(meta["dav2.pos_grid"]), pos_offset=float(meta["dav2.pos_offset"]),
                       head_hidden=int(meta["dav2.head_hidden"]), norm_eps=float(meta["dav2.norm_eps"]))


def import_ampw(path: str) -> dav2.DepthAnythingV2:
    """The twin rebuilt from a weight file (LayerScale 1, unused tensors zero), eval mode:
    the reference the C++ parity fixtures are computed with."""
    meta, tensors = read_ampw(path)
    if meta.get("arch") != ARCH_NAME:
        raise CheckpointError(f"{path}: architecture {meta.get('arch')!r} is not {ARCH_NAME}")
    model = dav2.build(config_from_metadata(meta))
    state = {}
    for name, like in model.state_dict().items():
        if name in tensors:
            state[name] = from_file_layout(name, tensors[name], like)
        elif name.endswith(("ls1.gamma", "ls2.gamma")):
            state[name] = torch.ones_like(like)
        elif is_unused(name):
            state[name] = torch.zeros_like(like)
        else:
            raise CheckpointError(f"{path}: no tensor {name!r}")
    unknown = sorted(set(tensors) - set(state))
    if unknown:
        raise CheckpointError(f"{path}: unexpected tensor {unknown[0]!r}")
    model.load_state_dict(state, strict=True)
    return model.eval()


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("checkpoint", help="depth_anything_v2_vits.pth (or vitb, vitl)")
    p.add_argument("output", help="the .ampw file to write")
    args = p.parse_args(argv)
    try:
        meta = convert(args.checkpoint, args.output)
    except (CheckpointError, AmpwError) as e:
        print(str(e), file=sys.stderr)
        return 1
    size = Path(args.output).stat().st_size
    print(f"{args.output}: Depth Anything V2 {meta['depth.variant']}, {meta['depth.parameters']:,} parameters, "
          f"{size / 1e6:.1f} MB (licence {meta['source.licence']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Photo textures: the mip-mapped photos of one split, and the material that tiles a
crop of one of them over a surface.

A pool is built once per process (texture_pool) and shared by forked DataLoader workers.
Texels are stored as sRGB and come out of sample_bilinear in linear light, where the
renderer lights them.
"""

import functools
from dataclasses import dataclass

import numpy as np
import torch

from photo_folder import is_validation_seed, list_photos, load_photo, ordinal_split

TEXTURE_MAX_SIDE = 512            # photos are downscaled to this before mip-mapping

# Colours are stored as sRGB and lit in linear light; gamma 2 stands in for the sRGB curve
# because it costs a multiply instead of a power (sample_bilinear squares, and
# camera_effects.photograph encodes with about 1 / DISPLAY_GAMMA).
DISPLAY_GAMMA = 2.0


def mip_pyramid(image, min_side=8):
    """Levels of 2x2 box-averaged copies, finest first, down to min_side pixels, as
    uint8 tensors (3, h, w): the layout torch's grid_sample reads."""
    levels = [image]
    while min(levels[-1].shape[:2]) >= 2 * min_side:
        top = levels[-1]
        h, w = top.shape[0] // 2 * 2, top.shape[1] // 2 * 2
        a = top[:h, :w].astype(np.uint16)
        mean = (a[0::2, 0::2] + a[1::2, 0::2] + a[0::2, 1::2] + a[1::2, 1::2] + 2) // 4
        levels.append(mean.astype(np.uint8))
    return [torch.from_numpy(np.ascontiguousarray(level.transpose(2, 0, 1))) for level in levels]


class TexturePool:
    """Mip pyramids of the photos of one split; built once per process (see texture_pool)."""

    def __init__(self, paths):
        self.paths = list(paths)
        self.pyramids = [mip_pyramid(load_photo(p, TEXTURE_MAX_SIDE)) for p in self.paths]


@functools.lru_cache(maxsize=None)
def texture_pool(split):
    """The process-wide pool of 'train' or 'val' photos; forked DataLoader workers share it.
    Training textures leave out the ordinal validation photos as well."""
    paths = list_photos(split)
    if split == 'train':
        paths = [p for p in paths if ordinal_split(p) == 'train']
    return TexturePool(paths)


def pool_for_seed(seed):
    return texture_pool('val' if is_validation_seed(seed) else 'train')


def mirror(x, size):
    """Mirrored repeat of x into [0, size]: tiling a photo crop without visible seams."""
    period = 2 * size
    x = x - np.floor(x * (1 / period)) * period
    return np.minimum(x, period - x)


def sample_bilinear(image, crop, x, y):
    """Linear RGB (3, N) of image (uint8 tensor 3 x h x w) at texel coordinates (x, y),
    tiled by mirroring inside crop (x, y, w, h)."""
    cx, cy, cw, ch = crop
    h, w = image.shape[1:]
    # Clamped to the image (what grid_sample's border padding reads anyway): a crop scaled
    # to a coarse mip level can reach past the last texel, and in float32 the mirrored
    # repeat of a huge coordinate (a far surface at a grazing angle) can come out a few
    # texels below 0, whose negative slice start left the patch below empty (a training
    # run stopped on it at step 4,480).
    x = np.clip(mirror(x, max(cw - 1, 1)) + cx, 0, w - 1)
    y = np.clip(mirror(y, max(ch - 1, 1)) + cy, 0, h - 1)
    # Only the texels in reach are converted to float for grid_sample.
    x0, y0 = int(x.min()), int(y.min())
    x1, y1 = min(w, int(x.max()) + 2), min(h, int(y.max()) + 2)
    grid = np.stack([(x - x0) * (2 / max(x1 - x0 - 1, 1)) - 1,
                     (y - y0) * (2 / max(y1 - y0 - 1, 1)) - 1], axis=-1)
    patch = image[None, :, y0:y1, x0:x1].float()
    grid = torch.from_numpy(grid.astype(np.float32, copy=False))[None, None]
    srgb = torch.nn.functional.grid_sample(patch, grid, mode='bilinear', padding_mode='border',
                                           align_corners=True)[0, :, 0].numpy()
    srgb = srgb * np.float32(1 / 255)
    return srgb * srgb


@dataclass
class Material:
    """Linear albedo (3, N): tint alone, or tint times a photo crop tiled over the surface."""
    tint: np.ndarray
    pyramid: list = None            # mip levels (uint8 sRGB tensors, 3 x h x w) of one photo
    crop: tuple = (0, 0, 1, 1)      # x, y, w, h of the tiled region in level-0 texels
    texels_per_metre: float = 100.0
    offset: tuple = (0.0, 0.0)      # texels
    stretch: float = 1.0            # > 1: the crop drawn taller than wide, vertical streaks

    def albedo(self, uv, metres_per_pixel):
        count = np.size(uv[0])
        if self.pyramid is None:
            return np.broadcast_to(self.tint.astype(np.float32)[:, None], (3, count))
        tu = uv[0] * self.texels_per_metre + self.offset[0]
        tv = -uv[1] * (self.texels_per_metre / self.stretch) + self.offset[1]   # rows grow downwards
        footprint = np.maximum(metres_per_pixel * self.texels_per_metre, 1e-6)
        levels = np.clip(np.rint(np.log2(footprint)), 0, len(self.pyramid) - 1).astype(np.uint8)
        lowest = int(levels.min())
        if lowest == levels.max():
            return self._sample_level(lowest, tu, tv)
        # Group the pixels by level with one (radix) sort: cheaper than a mask per level.
        order = np.argsort(levels, kind='stable')
        tu, tv = tu[order], tv[order]
        ends = np.cumsum(np.bincount(levels, minlength=len(self.pyramid)))
        pieces = [self._sample_level(level, tu[start:end], tv[start:end])
                  for level, (start, end) in enumerate(zip(np.r_[0, ends[:-1]], ends)) if end > start]
        out = np.empty((3, count), dtype=np.float32)
        out[:, order] = np.concatenate(pieces, axis=1)
        return out

    def _sample_level(self, level, tu, tv):
        scale = 0.5 ** level
        crop = tuple(c * scale for c in self.crop)
        return sample_bilinear(self.pyramid[level], crop, tu * scale, tv * scale) * self.tint[:, None]

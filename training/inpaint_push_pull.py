"""The inpainting network's prefills in numpy, step for step: push-pull
(inpaint/push_pull.cpp) and the harmonic fill built on it (inpaint/harmonic_fill.cpp),
so the network trains on exactly the pre-fill the C++ filler gives it at inference.

The C++ version builds a pyramid with cv::resize: INTER_AREA to halve ((n + 1) / 2 per
side), INTER_LINEAR to come back up. OpenCV is not available to this Python, so both
resamplings are written here as the weight matrices OpenCV's own tables describe
(computeResizeAreaTab for INTER_AREA, the half-pixel-centre coefficients with clamped
edges for INTER_LINEAR) and applied separably, in float32 as OpenCV does. The result is
rounded to 8 bits like the C++ one. tests/inpaint/test_prefill_parity.cpp checks the
two agree on fixtures written by this module (`write_fixture`).
"""
from __future__ import annotations

import functools
import math

import numpy as np


@functools.lru_cache(maxsize=None)
def area_matrix(src: int, dst: int) -> np.ndarray:
    """[dst, src] weights of OpenCV's INTER_AREA down-scaling along one axis."""
    m = np.zeros((dst, src), np.float32)
    if src == dst:
        np.fill_diagonal(m, 1.0)
        return m
    scale = 1.0 / (dst / src)  # as cv::resize derives it from the sizes
    for dx in range(dst):
        fsx1 = dx * scale
        fsx2 = fsx1 + scale
        cell = min(scale, src - fsx1)
        sx1, sx2 = math.ceil(fsx1), math.floor(fsx2)
        sx2 = min(sx2, src - 1)
        sx1 = min(sx1, sx2)
        if sx1 - fsx1 > 1e-3:
            m[dx, sx1 - 1] += np.float32((sx1 - fsx1) / cell)
        for sx in range(sx1, sx2):
            m[dx, sx] += np.float32(1.0 / cell)
        if fsx2 - sx2 > 1e-3:
            m[dx, sx2] += np.float32(min(min(fsx2 - sx2, 1.0), cell) / cell)
    return m


@functools.lru_cache(maxsize=None)
def linear_matrix(src: int, dst: int) -> np.ndarray:
    """[dst, src] weights of OpenCV's INTER_LINEAR resampling along one axis: pixel
    centres aligned, edges clamped."""
    m = np.zeros((dst, src), np.float32)
    if src == dst:
        np.fill_diagonal(m, 1.0)
        return m
    scale = 1.0 / (dst / src)
    for dx in range(dst):
        fx = np.float32((dx + 0.5) * scale - 0.5)
        sx = math.floor(fx)
        fx = np.float32(fx - sx)
        if sx < 0:
            fx, sx = np.float32(0), 0
        if sx >= src - 1:
            fx, sx = np.float32(0), src - 1
        m[dx, sx] += np.float32(1) - fx
        if fx != 0:
            m[dx, sx + 1] += fx
    return m


def resample(x: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """rows [H', H] @ x [H, W, C] @ cols^T [W, W'] per channel, in float32."""
    h, w, c = x.shape
    y = (rows @ x.reshape(h, w * c)).reshape(-1, w, c)
    return np.ascontiguousarray((cols @ y).astype(np.float32, copy=False))


def push(colour: np.ndarray, weight: np.ndarray):
    """One level down: confidence-weighted averages, confidence at most 1."""
    h, w = weight.shape[:2]
    both = resample(np.concatenate([colour, weight], -1), area_matrix(h, (h + 1) // 2),
                    area_matrix(w, (w + 1) // 2))
    colour, weight = both[..., :3], both[..., 3:]
    scale = np.minimum(weight * np.float32(4.0), np.float32(1.0))
    factor = scale / np.maximum(weight, np.float32(1e-12))
    return (colour * factor).astype(np.float32), scale.astype(np.float32)


def push_pull_float(rgb: np.ndarray, known: np.ndarray) -> np.ndarray:
    """rgb [H, W, 3] (any float scale), known [H, W] bool. Returns the float estimate at
    every pixel (the known colour where known), or None when nothing is known."""
    weight = (known > 0).astype(np.float32)[..., None]
    if not weight.any():
        return None
    levels = [(rgb.astype(np.float32) * weight, weight)]
    while levels[-1][1].shape[0] > 1 or levels[-1][1].shape[1] > 1:
        levels.append(push(*levels[-1]))
    colour, weight = levels[-1]
    estimate = (colour / np.float32(max(1e-12, float(weight[0, 0, 0])))).astype(np.float32)
    for colour, weight in reversed(levels[:-1]):
        h, w = weight.shape[:2]
        eh, ew = estimate.shape[:2]
        up = resample(estimate, linear_matrix(eh, h), linear_matrix(ew, w))
        estimate = colour + up * (np.float32(1.0) - weight)
    return estimate


def push_pull_fill(image: np.ndarray, known: np.ndarray, fill: np.ndarray, **_params) -> np.ndarray:
    """As ampi::push_pull_fill: image uint8 [H, W, 3]; the pixels where fill is set take the
    8-bit push-pull estimate from the known pixels, every other pixel is unchanged."""
    return paste_estimate(image, push_pull_float(image, known), fill)


def paste_estimate(image: np.ndarray, estimate, fill: np.ndarray) -> np.ndarray:
    """As ampi::paste_estimate: a copy of image whose pixels where fill is set take the
    8-bit rounding of estimate (None: nothing was known, image unchanged)."""
    out = image.copy()
    if estimate is not None:
        filled = np.clip(np.rint(estimate), 0, 255).astype(np.uint8)
        out[fill > 0] = filled[fill > 0]
    return out


# inpaint/harmonic_fill.h HarmonicFill and kKnownShare
HARMONIC_COARSEST_SIDE, HARMONIC_START_SIDE = 256, 1024
HARMONIC_COARSEST_SWEEPS, HARMONIC_SWEEPS, HARMONIC_BAND = 100, 25, 48
HARMONIC_OMEGA, HARMONIC_KNOWN_SHARE = 1.95, 0.5


def dilate(mask: np.ndarray, iterations: int) -> np.ndarray:
    """cv::dilate with a 3x3 element `iterations` times; outside the image counts as
    unset."""
    for _ in range(iterations):
        grown = mask.copy()
        grown[1:] |= mask[:-1]
        grown[:-1] |= mask[1:]
        rows = grown.copy()
        grown[:, 1:] |= rows[:, :-1]
        grown[:, :-1] |= rows[:, 1:]
        mask = grown
    return mask


def relax(f: np.ndarray, known: np.ndarray, sweeps: int, omega: float, band: int = 0):
    """`sweeps` red-black over-relaxation sweeps of f [H, W, 3] in place, known [H, W]
    kept (and, when band > 0, every pixel more than `band` 3x3 dilations from them): each
    other pixel of one colour ((x + y) & 1) moves omega of the way to the mean of its
    neighbours inside the image, then the other colour."""
    if band > 0:
        known = known | ~dilate(known, band)
    h, w = known.shape
    count = np.zeros((h, w, 1), np.float32)  # neighbours inside the image
    count[:, 1:] += 1
    count[:, :-1] += 1
    count[1:] += 1
    count[:-1] += 1
    count = np.maximum(count, np.float32(1))  # a 1x1 image: no neighbour, no step
    parity = np.add.outer(np.arange(h), np.arange(w)) & 1
    # 1 on the unknown pixels of each colour: multiplying a step by it is exact
    colours = [((parity == c) & ~known).astype(np.float32)[..., None] for c in (0, 1)]
    omega = np.float32(omega)
    for _ in range(sweeps):
        for mask in colours:
            total = np.zeros_like(f)  # left, right, up, down, as the C++ sums them
            total[:, 1:] += f[:, :-1]
            total[:, :-1] += f[:, 1:]
            total[1:] += f[:-1]
            total[:-1] += f[1:]
            f += omega * (total / count - f) * mask


def harmonic_float(rgb: np.ndarray, known: np.ndarray, coarsest_side: int = HARMONIC_COARSEST_SIDE,
                   coarsest_sweeps: int = HARMONIC_COARSEST_SWEEPS, sweeps: int = HARMONIC_SWEEPS,
                   band: int = HARMONIC_BAND, omega: float = HARMONIC_OMEGA,
                   start_side: int = HARMONIC_START_SIDE) -> np.ndarray:
    """As ampi::harmonic_estimate: Laplace's equation on the unknown pixels, solved by
    over-relaxation as a cascade above coarsest_side, push-pull (made at most start_side
    large) starting the coarsest level; None when nothing is known."""
    known = known > 0
    if not known.any():
        return None
    levels = [(rgb.astype(np.float32), known)]
    weight = known.astype(np.float32)[..., None]  # known share of each cell
    weighted = levels[0][0] * weight  # colour x that share
    while max(levels[-1][1].shape) > coarsest_side:
        h, w = levels[-1][1].shape
        rows, cols = area_matrix(h, (h + 1) // 2), area_matrix(w, (w + 1) // 2)
        weight, weighted = resample(weight, rows, cols), resample(weighted, rows, cols)
        coarse_known = weight[..., 0] >= np.float32(HARMONIC_KNOWN_SHARE)
        if not coarse_known.any():
            break  # scattered known pixels: stay finer
        colour = np.zeros(weighted.shape, np.float32)
        colour[coarse_known] = (weighted / np.maximum(weight, np.float32(1e-12)))[coarse_known]
        levels.append((colour, coarse_known))
    first = next(i for i, (_, k) in enumerate(levels) if max(k.shape) <= start_side or i + 1 == len(levels))
    estimate = push_pull_float(*levels[first])
    for colour, level_known in levels[first + 1:]:  # averaged down, known cells set
        h, w = level_known.shape
        estimate = resample(estimate, area_matrix(estimate.shape[0], h), area_matrix(estimate.shape[1], w))
        estimate[level_known] = colour[level_known]
    relax(estimate, levels[-1][1], coarsest_sweeps, omega)
    for colour, level_known in reversed(levels[:-1]):
        (h, w), (eh, ew) = level_known.shape, estimate.shape[:2]
        up = resample(estimate, linear_matrix(eh, h), linear_matrix(ew, w))
        estimate = np.where(level_known[..., None], colour, up).astype(np.float32)
        relax(estimate, level_known, sweeps, omega, band)
    return estimate


def harmonic_fill(image: np.ndarray, known: np.ndarray, fill: np.ndarray, **params) -> np.ndarray:
    """As ampi::harmonic_fill: image uint8 [H, W, 3]; the pixels where fill is set take the
    8-bit harmonic estimate from the known pixels (params: harmonic_float's), every other
    pixel is unchanged."""
    return paste_estimate(image, harmonic_float(image, known, **params), fill)


PREFILLS = {"push-pull": push_pull_fill, "harmonic": harmonic_fill}  # by inpaint.prefill name


def write_fixture(path: str, seed: int, height: int, width: int, method: str = "push-pull", **params):
    """A random image with a blob, a band and scattered known pixels, and its fill by
    `method` (a PREFILLS name, with integer `params`, which go into the metadata), for
    the C++ parity test (image, known, fill and expected as float tensors)."""
    import os
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    from weights_format.ampw import write_ampw

    rng = np.random.default_rng(seed)
    # smooth colour plus noise: push-pull's averages then land between integers, so the
    # comparison exercises rounding and not just copying
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    base = np.stack([128 + 100 * np.sin(xx / 7 + c) * np.cos(yy / 5 - c) for c in range(3)], -1)
    image = np.clip(base + rng.normal(0, 20, base.shape), 0, 255).astype(np.uint8)
    known = ((yy - height / 2) ** 2 + (xx - width / 3) ** 2 > (min(height, width) / 3) ** 2)
    known &= ~((xx > width * 0.7) & (xx < width * 0.7 + 4))
    known &= rng.random((height, width)) > 0.1
    fill = ~known
    expected = PREFILLS[method](image, known, fill, **params)
    f32 = lambda a: np.ascontiguousarray(a, dtype=np.float32)  # noqa: E731
    write_ampw(path, {"image": f32(image), "known": f32(known), "fill": f32(fill),
                      "expected": f32(expected)}, {"seed": seed, **params})

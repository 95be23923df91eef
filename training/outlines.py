"""Random outlines and smooth noise: the cut-out masks of flat objects (blobs, foliage,
people, animals), the skyline of backdrops and facades, and the clouds' noise.

A mask is a boolean array, row 0 at the top; a shapes.Quad cut out by one shows only
where it is True.
"""

import math

import numpy as np


def interpolation_matrix(n_out, n_in):
    """(n_out, n_in) weights of linear interpolation from n_in samples to n_out."""
    position = np.linspace(0, n_in - 1, n_out)
    lower = np.minimum(np.floor(position).astype(int), n_in - 2)
    frac = position - lower
    weights = np.zeros((n_out, n_in), dtype=np.float32)
    weights[np.arange(n_out), lower] = 1 - frac
    weights[np.arange(n_out), lower + 1] = frac
    return weights


def smooth_noise(rng, shape, cells, octaves=3):
    """Fractal value noise in [0, 1]: random grids of cells, cells*2, ... upsampled."""
    total = np.zeros(shape, dtype=np.float32)
    amplitude, norm = 1.0, 0.0
    for octave in range(octaves):
        n = cells * 2 ** octave
        grid = rng.random((n + 1, n + 1)).astype(np.float32)
        total += amplitude * (interpolation_matrix(shape[0], n + 1) @ grid @ interpolation_matrix(shape[1], n + 1).T)
        norm += amplitude
        amplitude *= 0.5
    total /= norm
    return (total - total.min()) / max(float(total.max() - total.min()), 1e-6)


def blob_mask(rng, size=96):
    """A star-shaped outline: radius is a random sum of harmonics of the angle."""
    y, x = np.mgrid[-1:1:size * 1j, -1:1:size * 1j]
    angle = np.arctan2(y, x)
    radius = np.ones_like(angle)
    for k in range(1, 7):
        radius += rng.normal(0, 0.25 / k) * np.cos(k * angle + rng.uniform(0, 2 * math.pi))
    return np.hypot(x, y) < 0.9 * radius / max(float(radius.max()), 1e-6)


def foliage_mask(rng, size=96):
    """Thresholded noise inside an ellipse: ragged edges and holes, like a bush."""
    y, x = np.mgrid[-1:1:size * 1j, -1:1:size * 1j]
    noise = smooth_noise(rng, (size, size), rng.integers(3, 7), octaves=4)
    return noise - 0.9 * (x * x + y * y) > rng.uniform(-0.25, 0.1)


def figure_mask(rng, rows=128, cols=64):
    """A standing person's outline: head, torso, two legs, two arms, slightly wobbly."""
    y, x = np.mgrid[0:1:rows * 1j, -0.5:0.5:cols * 1j]
    x = x + 0.03 * np.sin(y * rng.uniform(5, 15) + rng.uniform(0, 6))
    head_r = rng.uniform(0.055, 0.075)
    shoulder = rng.uniform(0.14, 0.2)
    hip_y = rng.uniform(0.5, 0.58)
    head = (x / 0.8) ** 2 + (y - head_r - 0.01) ** 2 < head_r ** 2
    torso = (np.abs(x) < shoulder * (1 - 0.3 * (y - 0.15))) & (y > 2 * head_r) & (y < hip_y)
    stride = rng.uniform(0.02, 0.12)
    legs = (y >= hip_y - 0.02) & (np.abs(np.abs(x) - 0.05 - stride * (y - hip_y)) < 0.055)
    arm_spread = rng.uniform(0.0, 0.25)
    arms = ((y > 2 * head_r + 0.02) & (y < hip_y + 0.05)
            & (np.abs(np.abs(x) - shoulder - arm_spread * (y - 0.2)) < 0.035))
    return head | torso | legs | arms


def animal_mask(rng, rows=64, cols=112):
    """A four-legged animal's side view: body, neck and head, legs, tail."""
    y, x = np.mgrid[0:1:rows * 1j, 0:1:cols * 1j]
    facing = 1 if rng.random() < 0.5 else -1
    x = 0.5 + facing * (x - 0.5)
    belly = rng.uniform(0.5, 0.62)
    body = ((x - 0.5) / 0.3) ** 2 + ((y - (belly - 0.16)) / 0.17) ** 2 < 1
    neck_top = rng.uniform(0.05, 0.25)
    neck = (x > 0.7) & (x < 0.82) & (y > neck_top + 0.05) & (y < belly - 0.15) & (np.abs(x - 0.76 + 0.2 * (y - belly)) < 0.07)
    head = ((x - 0.85) / 0.1) ** 2 + ((y - neck_top - 0.06) / 0.07) ** 2 < 1
    legs = np.zeros_like(body)
    for centre in (0.27, 0.36, 0.64, 0.73):
        legs |= (np.abs(x - centre - rng.uniform(-0.03, 0.03)) < 0.035) & (y > belly - 0.2)
    tail = (x < 0.22) & (x > 0.12) & (np.abs(y - (belly - 0.3) - 0.8 * (0.22 - x)) < 0.03)
    return body | neck | head | legs | tail


def skyline_mask(rng, rows=64, cols=256, blocky=False):
    """Columns filled from the bottom to a ridge (smooth) or roof-line (blocky) profile."""
    if blocky:
        heights = np.empty(cols, dtype=np.float32)
        start = 0
        while start < cols:
            width = rng.integers(cols // 40 + 1, cols // 8 + 2)
            heights[start:start + width] = rng.uniform(0.3, 1.0)
            start += width
    else:
        heights = 0.25 + 0.75 * smooth_noise(rng, (1, cols), rng.integers(2, 6), octaves=4)[0]
    level = 1 - (np.arange(rows, dtype=np.float32)[:, None] + 0.5) / rows
    return level <= heights[None, :]


def random_mask(rng, kind):
    makers = {'blob': blob_mask, 'foliage': foliage_mask, 'figure': figure_mask, 'animal': animal_mask}
    while True:      # a rare draw covers almost nothing: draw again
        mask = makers[kind](rng)
        if mask.mean() > 0.08:
            return mask

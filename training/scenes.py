#!/usr/bin/env python3
"""Procedural RGB-D scenes with exact disparity, for training the depth networks: the
generator's entry point (render_scene, SceneDataset) and its command line.

A scene is a pinhole camera above a ground plane, a background (open land under a sky
with far backdrops, a street between facades, or a room) and many textured objects.
Every pixel's ray is intersected analytically with every shape whose screen box holds
the pixel, so occlusions and disparity (1 / camera depth) are exact. Colours come from
crops of the real photos in ../shared/data/photos, lit by a directional light with cast
shadows, hazed with distance, and passed through a random camera (defocus, optical
softness, white balance, gamma, noise, JPEG).

    /usr/bin/python3 training/scenes.py --bench
    /usr/bin/python3 training/scenes.py --contact-sheet training/scenes_contact_sheet.jpg

The stages live beside this file: scene_sampler.py draws a scene from a seed,
raytracer.py renders it (with shapes.py and textures.py), camera_effects.py makes the
photo; photo_folder.py lists the photos and splits them, outlines.py draws cut-outs.
"""

import argparse
import math
import os
import sys
import time

import numpy as np
import torch
from PIL import Image

from camera_effects import photograph
from photo_folder import is_validation_seed
from raytracer import render
from scene_sampler import sample_scene
from textures import pool_for_seed, texture_pool

DEFAULT_SIZE = (384, 288)


def render_scene(seed, width=DEFAULT_SIZE[0], height=DEFAULT_SIZE[1]):
    """(rgb uint8 HxWx3, disparity float32 HxW): one random photo-like scene, exact 1/depth.

    Deterministic by seed; seeds >= 10**9 are validation scenes textured only with the
    validation photos, the others only with the training photos."""
    scene = sample_scene(seed, width, height)
    radiance, disparity = render(scene)
    rng = np.random.default_rng([seed, 1])      # the camera's own stream: edits to shading keep it
    return photograph(radiance, disparity, rng), disparity


class SceneDataset(torch.utils.data.Dataset):
    """Scenes seed_start .. seed_start + count - 1 as (image, disparity) tensors.

    image: float32 (3, H, W) in [0, 1]; disparity: float32 (1, H, W), 1 / depth in 1/metres,
    0 for sky. size = (width, height). The texture pool is loaded here, before a
    DataLoader forks its workers, so that they share it."""

    def __init__(self, seed_start, count, size=DEFAULT_SIZE):
        if is_validation_seed(seed_start) != is_validation_seed(seed_start + max(count, 1) - 1):
            raise ValueError(f'seeds {seed_start}..{seed_start + count - 1} mix training and validation')
        self.seed_start, self.count = seed_start, count
        self.width, self.height = size
        pool_for_seed(seed_start)

    def __len__(self):
        return self.count

    def __getitem__(self, index):
        if not 0 <= index < self.count:
            raise IndexError(f'scene {index} outside 0..{self.count - 1}')
        rgb, disparity = render_scene(self.seed_start + index, self.width, self.height)
        image = torch.from_numpy(rgb).permute(2, 0, 1).float().div_(255)
        return image, torch.from_numpy(disparity)[None]


# ----------------------------------------------------------------------------------
# Command line: benchmark and contact sheet

DISPARITY_COLOURS = np.array([        # far (dark violet) to near (pale yellow)
    [0.02, 0.02, 0.10], [0.30, 0.08, 0.50], [0.75, 0.20, 0.45], [0.98, 0.55, 0.18], [0.99, 0.95, 0.65]])


def colour_disparity(disparity):
    """uint8 RGB picture of disparity, normalised by its 99th percentile."""
    scale = max(float(np.percentile(disparity, 99)), 1e-6)
    x = np.clip(disparity / scale, 0, 1) * (len(DISPARITY_COLOURS) - 1)
    i = np.minimum(x.astype(np.int32), len(DISPARITY_COLOURS) - 2)
    f = (x - i)[..., None]
    rgb = DISPARITY_COLOURS[i] * (1 - f) + DISPARITY_COLOURS[i + 1] * f
    return (rgb * 255 + 0.5).astype(np.uint8)


def contact_sheet(path, seeds, tile=(192, 144), columns=3):
    """A grid of (photo | disparity) pairs, rendered at full size and shown downscaled."""
    tw, th = tile
    rows = math.ceil(len(seeds) / columns)
    sheet = np.full((rows * (th + 4), columns * (2 * tw + 8), 3), 255, dtype=np.uint8)
    for k, seed in enumerate(seeds):
        rgb, disparity = render_scene(seed)
        r, c = divmod(k, columns)
        y, x = r * (th + 4), c * (2 * tw + 8)
        for j, picture in enumerate((rgb, colour_disparity(disparity))):
            small = Image.fromarray(picture).resize(tile, Image.BILINEAR, reducing_gap=2.0)
            sheet[y:y + th, x + j * tw:x + (j + 1) * tw] = np.asarray(small)
    Image.fromarray(sheet).save(path, optimize=True, quality=90)  # quality: JPEG only


def benchmark(count, workers, size):
    """Prints images per second, in this process and through a DataLoader.

    The machine is often shared, so the CPU time per image and the load average are
    printed too: 1000 / (CPU ms per image) is the rate of one core of one's own."""
    texture_pool('train')
    wall, cpu = time.perf_counter(), time.process_time()
    for seed in range(count):
        render_scene(seed, *size)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(f'render_scene {size[0]}x{size[1]}: {count / wall:.1f} images/s in one process, '
          f'{1000 * cpu / count:.1f} ms of CPU per image ({count / cpu:.1f} images/s per free core)')
    if workers > 0:
        loader = torch.utils.data.DataLoader(SceneDataset(count, count, size), batch_size=8,
                                             num_workers=workers)
        start = time.perf_counter()
        for _ in loader:
            pass
        rate = count / (time.perf_counter() - start)
        print(f'SceneDataset + DataLoader, {workers} workers: {rate:.1f} images/s')
    print('load average (1, 5, 15 min): {:.1f} {:.1f} {:.1f} on {} cores'.format(*os.getloadavg(), os.cpu_count()))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--bench', type=int, nargs='?', const=200, metavar='COUNT',
                        help='render COUNT scenes (default 200) and print images/s')
    parser.add_argument('--workers', type=int, default=2, help='DataLoader workers for --bench')
    parser.add_argument('--size', type=int, nargs=2, default=DEFAULT_SIZE, metavar=('W', 'H'))
    parser.add_argument('--contact-sheet', metavar='PNG', help='write a grid of sample scenes')
    parser.add_argument('--seeds', type=int, nargs='+', default=list(range(12)),
                        help='seeds shown on the contact sheet')
    args = parser.parse_args(argv)
    if args.bench is None and args.contact_sheet is None:
        parser.error('nothing to do: give --bench and/or --contact-sheet')
    try:
        if args.contact_sheet:
            contact_sheet(args.contact_sheet, args.seeds)
        if args.bench is not None:
            benchmark(args.bench, args.workers, tuple(args.size))
    except (RuntimeError, ValueError, OSError) as error:
        print(f'scenes.py: {error}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())

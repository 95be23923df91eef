#!/usr/bin/env python3
"""A folder of synthetic photos with exact disparity references, for `ampi eval depth`.

    /usr/bin/python3 training/make_eval_scenes.py OUT [--count 50] [--size 384 288]

writes OUT/images/scene_NNNN.png (8-bit RGB) and OUT/reference/scene_NNNN.npy (float32
H x W disparity, 1/metres, larger = nearer; the sky is 0, which ampi eval depth leaves
out as unmeasured). The scenes are training/scenes.py's fixed validation seeds
(10**9, 10**9 + 1, ...): textured only with validation photos and never trained on.
Deterministic: the same arguments write the same files.
"""

import argparse
import sys
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
import photo_folder  # noqa: E402
import scenes  # noqa: E402


def write_scenes(out, count, size):
    images, reference = Path(out) / 'images', Path(out) / 'reference'
    images.mkdir(parents=True, exist_ok=True)
    reference.mkdir(parents=True, exist_ok=True)
    for i in range(count):
        seed = photo_folder.VALIDATION_SEED_START + i
        assert photo_folder.is_validation_seed(seed)
        rgb, disparity = scenes.render_scene(seed, *size)
        name = f'scene_{i:04d}'
        Image.fromarray(rgb).save(images / f'{name}.png')
        np.save(reference / f'{name}.npy', disparity.astype(np.float32))
        print(f'{name}: seed {seed}, {size[0]}x{size[1]}', file=sys.stderr)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('out', help='output folder (images/ and reference/ are made in it)')
    parser.add_argument('--count', type=int, default=50, help='number of scenes (default 50)')
    parser.add_argument('--size', type=int, nargs=2, default=scenes.DEFAULT_SIZE, metavar=('W', 'H'))
    args = parser.parse_args(argv)
    if args.count < 1 or min(args.size) < 16:
        parser.error('--count must be at least 1 and --size at least 16 x 16')
    try:
        write_scenes(args.out, args.count, tuple(args.size))
    except (RuntimeError, ValueError, OSError) as error:
        print(f'make_eval_scenes.py: {error}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())

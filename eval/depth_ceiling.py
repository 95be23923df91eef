#!/usr/bin/env python3
"""Where a depth network's synthetic delta < 1.25 goes: to the calibration of its output
(a disparity that is right in order but not an affine function of the true one) or to
its ordering (pixels in the wrong order).

    /usr/bin/python3 eval/depth_ceiling.py --ampi build/ampi --images /tmp/escenes/images \\
        --reference /tmp/escenes/reference [--weights weights/depth_lite.ampw]

Each image goes through `ampi depth` (the engine as a user runs it); its reference is
the .npy disparity training/make_eval_scenes.py writes (positive = measured, the sky
left out, as `ampi eval depth` reads it). The same prediction is scored three ways, each
the mean over the images of delta < 1.25 on the valid pixels:
  - median/std: the paper's alignment, what `ampi eval depth` reports;
  - least squares: the best affine map of the prediction;
  - rank-matched: every pixel takes the reference value of its rank, the best any
    increasing map of the prediction can do, so what it still misses is ordering.
Aligned values below the smallest reference value are raised to it, as in
eval/depth_eval.cpp.
"""

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

ALIGNMENTS = ('median/std', 'least squares', 'rank-matched')


def delta1(aligned: np.ndarray, reference: np.ndarray) -> float:
    aligned = np.maximum(aligned, reference.min())
    return float((np.maximum(aligned / reference, reference / aligned) < 1.25).mean())


def aligned_three_ways(p: np.ndarray, r: np.ndarray) -> list:
    """The prediction p aligned to the reference r (1-D, valid pixels only) by each of
    ALIGNMENTS."""
    p_std = p.std()
    median_std = (p - np.median(p)) * (r.std() / p_std if p_std > 0 else 0.0) + np.median(r)
    design = np.stack([p, np.ones_like(p)], axis=1)
    least_squares = design @ np.linalg.lstsq(design, r, rcond=None)[0]
    rank_matched = np.empty_like(r)
    rank_matched[np.argsort(p, kind='stable')] = np.sort(r)
    return [median_std, least_squares, rank_matched]


def scores(p: np.ndarray, r: np.ndarray) -> list:
    valid = r > 0
    if not valid.any():
        raise ValueError('no valid (positive) reference value')
    p, r = p[valid].astype(np.float64), r[valid].astype(np.float64)
    return [delta1(a, r) for a in aligned_three_ways(p, r)]


def predict(ampi: str, image: Path, out: Path, weights) -> np.ndarray:
    command = [ampi, 'depth', str(image), '-o', str(out)] + (['--weights', weights] if weights else [])
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f'depth_ceiling.py: {" ".join(command)} failed: {done.stderr.strip()}')
    return np.asarray(Image.open(out), dtype=np.float64)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--ampi', default='build/ampi')
    parser.add_argument('--images', required=True, help='the scenes (make_eval_scenes.py DIR/images)')
    parser.add_argument('--reference', required=True, help='their disparity, NAME.npy (DIR/reference)')
    parser.add_argument('--weights', help='a depth weight file (default: the bundled lite)')
    args = parser.parse_args(argv)
    images = sorted(Path(args.images).glob('*.png'))
    if not images:
        sys.exit(f'depth_ceiling.py: {args.images}: no .png scene')
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for image in images:
            reference = Path(args.reference) / f'{image.stem}.npy'
            if not reference.is_file():
                sys.exit(f'depth_ceiling.py: {reference}: missing (the reference of {image})')
            prediction = predict(args.ampi, image, Path(tmp) / 'disparity.png', args.weights)
            rows.append(scores(prediction, np.load(reference)))
    means = np.mean(rows, axis=0)
    print(f'{len(images)} scenes, {args.weights or "the bundled lite"}: delta < 1.25 after each alignment')
    for name, value in zip(ALIGNMENTS, means):
        print(f'{name:<14} {value:.3f}')


if __name__ == '__main__':
    main()

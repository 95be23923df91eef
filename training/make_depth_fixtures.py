"""Writes the parity fixtures of tests/nets/test_depth_net.cpp from the bundled weights.

    /usr/bin/python3 training/make_depth_fixtures.py

For each of weights/depth_lite.ampw and weights/depth_heavy.ampw, the PyTorch network is
rebuilt from the file (export_depth.import_ampw) and run on two small deterministic
images; the C++ network must reproduce the outputs. Rerun after replacing the weights.

tests/fixtures/nets/
  depth_input_64x96.npy          float32 [64, 96, 3], RGB in [0, 1] (a multiple of 32)
  depth_input_50x70.npy          float32 [50, 70, 3] (not a multiple: padding and cropping)
  depth_{lite,heavy}_64x96.npy   float32 [64, 96], the full-resolution output
  depth_{lite,heavy}_50x70.npy   float32 [50, 70]: the input padded by edge replication to
                                 64x96, run, and cropped back, as nets/ does
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
import export_depth  # noqa: E402

FIXTURES = ROOT / "tests" / "fixtures" / "nets"
SEED = 20210105


def test_image(height: int, width: int, seed: int) -> np.ndarray:
    """A synthetic scene-like picture: a vertical sky-to-ground ramp, a few flat
    rectangles and discs (depth edges to follow) and mild noise; no photo content."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    image = np.stack([0.3 + 0.5 * yy / height, 0.5 + 0.2 * np.sin(xx / 7.0), 0.8 - 0.6 * yy / height], -1)
    for _ in range(4):
        y0, x0 = rng.integers(0, height - 8), rng.integers(0, width - 8)
        h, w = rng.integers(6, height // 2), rng.integers(6, width // 2)
        colour = rng.random(3)
        if rng.random() < 0.5:
            image[y0:y0 + h, x0:x0 + w] = colour
        else:
            inside = ((yy - y0) / h) ** 2 + ((xx - x0) / w) ** 2 < 1.0
            image[inside] = colour
    image += rng.normal(0.0, 0.03, image.shape)
    return np.clip(image, 0.0, 1.0).astype(np.float32)


def run_padded(model, image: np.ndarray) -> np.ndarray:
    """The network on any size: edge-replicate to the multiple, run, crop."""
    h, w = image.shape[:2]
    m = model.multiple
    x = torch.from_numpy(image).permute(2, 0, 1)[None]
    x = F.pad(x, (0, (-w) % m, 0, (-h) % m), mode="replicate")
    with torch.no_grad():
        return model.predict(x)[0, 0, :h, :w].numpy().astype(np.float32)


def main():
    FIXTURES.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    inputs = {"64x96": test_image(64, 96, SEED), "50x70": test_image(50, 70, SEED + 1)}
    for size, image in inputs.items():
        np.save(FIXTURES / f"depth_input_{size}.npy", image)
    for variant in ("lite", "heavy"):
        model = export_depth.import_ampw(str(ROOT / "weights" / f"depth_{variant}.ampw"))
        for size, image in inputs.items():
            out = run_padded(model, image)
            np.save(FIXTURES / f"depth_{variant}_{size}.npy", out)
            print(f"{variant} {size}: output range [{out.min():.4f}, {out.max():.4f}]")


if __name__ == "__main__":
    main()

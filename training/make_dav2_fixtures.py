"""Writes the parity fixtures of the C++ Depth Anything V2 network (deterministic).

    /usr/bin/python3 training/make_dav2_fixtures.py [--out DIR]

A tiny model of the real architecture (depth_anything.TINY: embed 16, 5 blocks, 2 heads,
taps after blocks 0, 2, 3, 4, DPT features 8, projections 4/8/12/16, a 4x4 position
grid; not a trained model) gets seeded random weights, goes through the importer's
conversion (LayerScale folded, the file layouts) and is rebuilt from that file; the
rebuilt twin computes every expected output, so the C++ side must reproduce them from
the .ampw alone. Inputs are synthetic scenes (make_depth_fixtures.test_image).

tests/fixtures/nets/
  dav2_tiny.ampw                 the model file (arch ampi.depth.dav2-vit-dpt, variant tiny,
                                 depth.working_size 56: the infer case's size)
  dav2_tiny_input_56x56.npy      float32 [56, 56, 3], RGB in [0, 1]: the 4x4 patch grid, so the
                                 position embedding is used unchanged
  dav2_tiny_output_56x56.npy     float32 [56, 56]: the network on it (normalised inside)
  dav2_tiny_input_70x98.npy      float32 [70, 98, 3]: a 5x7 grid, the embedding interpolated
  dav2_tiny_output_70x98.npy     float32 [70, 98]
  dav2_tiny_pos_5x7.npy          float32 [36, 16]: the position embedding for that grid
                                 (row 0 the class token's), to test the bicubic on its own
  dav2_tiny_photo_45x61.npy      float32 [45, 61, 3]: a photo for the whole infer path at
                                 working size 56: cubic resize to 56x70, network, bilinear
  dav2_tiny_infer_45x61.npy      float32 [45, 61]: back to the photo's size (align_corners)
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import torch

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "weights_format"))
import depth_anything as dav2  # noqa: E402
import import_depth_anything as importer  # noqa: E402
from ampw import write_ampw  # noqa: E402
from make_depth_fixtures import test_image  # noqa: E402

FIXTURES = ROOT / "tests" / "fixtures" / "nets"
SEED = 22
WORKING_SIZE = 56  # the infer case's working size (4 patches)


def write_model(path: Path):
    """The tiny random-weight model, written the way the importer writes a checkpoint."""
    model = dav2.randomise_(dav2.build(dav2.TINY), SEED)
    provenance = {"source.file": f"random weights (depth_anything.randomise_, seed {SEED})",
                  "source.licence": "none (test fixture)", "import.tool": "training/make_dav2_fixtures.py"}
    tensors, meta = importer.ampw_contents(model.state_dict(), dav2.TINY, "tiny", provenance, WORKING_SIZE)
    write_ampw(str(path), tensors, meta)


@torch.no_grad()
def network(model, rgb: np.ndarray) -> np.ndarray:
    """The network on an RGB image whose sides are multiples of 14 (normalised, no resize)."""
    x = dav2.preprocess(rgb, size=min(rgb.shape[:2]))
    assert tuple(x.shape[-2:]) == rgb.shape[:2]
    return model(x)[0].numpy()


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default=str(FIXTURES))
    out = Path(p.parse_args(argv).out)
    out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    write_model(out / "dav2_tiny.ampw")
    model = importer.import_ampw(str(out / "dav2_tiny.ampw"))
    for i, (h, w) in enumerate(((56, 56), (70, 98))):
        rgb = test_image(h, w, SEED + i)
        result = network(model, rgb)
        np.save(out / f"dav2_tiny_input_{h}x{w}.npy", rgb)
        np.save(out / f"dav2_tiny_output_{h}x{w}.npy", result.astype(np.float32))
        print(f"network {h}x{w}: output range [{result.min():.4f}, {result.max():.4f}], "
              f"{(result > 0).mean():.0%} positive")
    pos = dav2.interpolate_pos_embed(model.pretrained.pos_embed.detach(), 5, 7, dav2.TINY.pos_offset)
    np.save(out / "dav2_tiny_pos_5x7.npy", pos[0].numpy().astype(np.float32))
    photo = test_image(45, 61, SEED + 2)
    result = dav2.infer(model, photo, size=WORKING_SIZE)
    np.save(out / "dav2_tiny_photo_45x61.npy", photo)
    np.save(out / "dav2_tiny_infer_45x61.npy", result.astype(np.float32))
    print(f"infer 45x61 via {dav2.working_shape(45, 61, WORKING_SIZE)}: range [{result.min():.4f}, "
          f"{result.max():.4f}]; model file {(out / 'dav2_tiny.ampw').stat().st_size:,} bytes")


if __name__ == "__main__":
    main()

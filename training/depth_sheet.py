"""Contact sheet of the validation photos (every tenth photo, never trained on) with the
disparity a bundled depth network predicts for them: what a user would see.

    /usr/bin/python3 training/depth_sheet.py weights/depth_lite.ampw training/depth_val_sheet.jpg

The network runs at the working size its weight file records (as `ampi depth` does), on
the photo scaled so its long side is that size and padded to the network's multiple; the
prediction is shown beside a thumbnail of the photo, near = warm, far = dark.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import torch
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "weights_format"))
import export_depth  # noqa: E402
import photo_folder  # noqa: E402
import scenes  # noqa: E402
from ampw import read_ampw  # noqa: E402

TILE_LONG_SIDE = 160
GAP = 4


def predict(model, rgb: np.ndarray, long_side: int, multiple: int) -> np.ndarray:
    """Disparity at the photo's working size (padding cropped off)."""
    h, w = rgb.shape[:2]
    scale = long_side / max(h, w)
    sw, sh = max(1, round(w * scale)), max(1, round(h * scale))
    small = np.asarray(Image.fromarray(rgb).resize((sw, sh), Image.BILINEAR), np.float32) / 255
    pw, ph = math.ceil(sw / multiple) * multiple, math.ceil(sh / multiple) * multiple
    padded = np.pad(small, ((0, ph - sh), (0, pw - sw), (0, 0)), mode="edge")
    x = torch.from_numpy(padded).permute(2, 0, 1)[None].contiguous(memory_format=torch.channels_last)
    with torch.no_grad():
        out = model.predict(x)[0, 0].numpy()
    return out[:sh, :sw]


def tile_pair(rgb: np.ndarray, disparity: np.ndarray) -> np.ndarray:
    """photo | coloured disparity, both scaled to TILE_LONG_SIDE."""
    h, w = rgb.shape[:2]
    scale = TILE_LONG_SIDE / max(h, w)
    size = (max(1, round(w * scale)), max(1, round(h * scale)))
    photo = np.asarray(Image.fromarray(rgb).resize(size, Image.BILINEAR))
    lo, hi = np.percentile(disparity, 1), np.percentile(disparity, 99)
    normalised = np.clip((disparity - lo) / max(hi - lo, 1e-6), 0, 1)
    colour = scenes.colour_disparity(normalised)
    colour = np.asarray(Image.fromarray(colour).resize(size, Image.BILINEAR))
    return np.concatenate([photo, np.full((size[1], GAP, 3), 255, np.uint8), colour], axis=1)


def sheet(tiles, columns: int) -> np.ndarray:
    cell_w = max(t.shape[1] for t in tiles) + 2 * GAP
    cell_h = max(t.shape[0] for t in tiles) + GAP
    rows = math.ceil(len(tiles) / columns)
    out = np.full((rows * cell_h, columns * cell_w, 3), 255, np.uint8)
    for k, t in enumerate(tiles):
        y, x = (k // columns) * cell_h, (k % columns) * cell_w
        out[y:y + t.shape[0], x:x + t.shape[1]] = t
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("weights", help="a depth .ampw file")
    p.add_argument("output", help="the PNG to write")
    p.add_argument("--photos", help="photo root (default: ../shared/data/photos)")
    p.add_argument("--count", type=int, default=16, help="photos shown, spread over the validation split")
    p.add_argument("--columns", type=int, default=4)
    args = p.parse_args(argv)
    meta, _ = read_ampw(args.weights)
    model = export_depth.import_ampw(args.weights)
    long_side, multiple = int(meta["depth.working_long_side"]), int(meta.get("depth.multiple", 32))
    photos = photo_folder.list_photos("val", args.photos)
    chosen = [photos[round(i * (len(photos) - 1) / max(1, args.count - 1))] for i in range(min(args.count, len(photos)))]
    tiles = []
    for path in chosen:
        rgb = photo_folder.load_photo(path, max_side=1024)
        tiles.append(tile_pair(rgb, predict(model, rgb, long_side, multiple)))
    Image.fromarray(sheet(tiles, args.columns)).save(args.output, optimize=True, quality=90)  # quality: JPEG only
    print(f"{args.output}: {len(tiles)} validation photos, {Path(args.weights).name} at long side {long_side}")


if __name__ == "__main__":
    main()

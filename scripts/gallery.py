#!/usr/bin/env python3
"""Makes the README's gallery from the bundled example: the depth map (colour-mapped),
the MPI's layers over a checkerboard, and a small animated GIF of the parallax video.

Run from the repository root after building (bash scripts/demo.sh builds):
    /usr/bin/python3 scripts/gallery.py
Writes docs/gallery/{depth.png, layers.png, parallax.gif}, and edges.png: `ampi eval
edges`'s disk scene with its depth made at a quarter of the size (photo, map, the exact
new view, the view before and after depth edges follow the photo, the camera moved as far
as ampi run's default path takes it). Needs ffmpeg for the GIF.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image

PHOTO = "examples/forest_path.jpg"
OUT = "docs/gallery"
THUMB_WIDTH = 384


def colour_map(d):
    """Disparity in [0, 1] to a perceptually ordered blue (far) -> yellow (near) ramp."""
    stops = np.array([[13, 8, 135], [126, 3, 168], [204, 71, 120], [248, 149, 64], [240, 249, 33]], float)
    x = np.clip(d, 0, 1) * (len(stops) - 1)
    i = np.minimum(x.astype(int), len(stops) - 2)
    f = (x - i)[..., None]
    return (stops[i] * (1 - f) + stops[i + 1] * f).astype(np.uint8)


def thumb(img):
    w, h = img.size
    return img.resize((THUMB_WIDTH, round(h * THUMB_WIDTH / w)), Image.LANCZOS)


def layers_sheet(mpi_dir):
    meta = json.load(open(os.path.join(mpi_dir, "mpi.json")))
    tiles = []
    for plane in meta["planes"]:
        layer = thumb(Image.open(os.path.join(mpi_dir, plane["layer"])).convert("RGBA"))
        w, h = layer.size
        yy, xx = np.mgrid[0:h, 0:w]
        checks = np.where(((xx // 12) + (yy // 12)) % 2 == 0, 200, 150).astype(np.uint8)
        board = Image.fromarray(np.stack([checks] * 3, -1)).convert("RGBA")
        tiles.append(Image.alpha_composite(board, layer).convert("RGB"))
    cols = 4
    rows = (len(tiles) + cols - 1) // cols
    w, h = tiles[0].size
    sheet = Image.new("RGB", (cols * w, rows * h), (255, 255, 255))
    for k, tile in enumerate(tiles):
        sheet.paste(tile, ((k % cols) * w, (k // cols) * h))
    return sheet


def main():
    ampi = os.path.join("build", "ampi")
    if not os.path.exists(ampi):
        sys.exit(f"{ampi}: not built (run bash scripts/demo.sh first)")
    os.makedirs(OUT, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        run_dir = os.path.join(tmp, "run")
        subprocess.run([ampi, "run", PHOTO, "-o", run_dir, "--frames", "60", "--quiet"], check=True)
        depth = np.asarray(Image.open(os.path.join(run_dir, "depth.png")), dtype=np.float64) / 65535.0
        thumb(Image.fromarray(colour_map(depth))).save(os.path.join(OUT, "depth.png"), optimize=True)
        layers_sheet(os.path.join(run_dir, "mpi")).save(os.path.join(OUT, "layers.png"), optimize=True)
        if shutil.which("ffmpeg") is None:
            sys.exit("ffmpeg: not found; the GIF needs it")
        gif = os.path.join(OUT, "parallax.gif")
        # 10 frames a second: the GIF travels to GPU machines with the working tree, against
        # a transfer limit (15 made it 2.7 MB)
        filters = f"fps=10,scale={THUMB_WIDTH}:-1:flags=lanczos,split[a][b];[a]palettegen[p];[b][p]paletteuse"
        subprocess.run(["ffmpeg", "-loglevel", "error", "-y", "-i", os.path.join(run_dir, "video.mp4"),
                        "-vf", filters, gif], check=True)
        edges_dir = os.path.join(tmp, "edges")
        subprocess.run([ampi, "eval", "edges", "--softness", "4", "--pose", "0.05,0,0", "--inpainter", "push-pull",
                        "-o", edges_dir], check=True, capture_output=True)
        strip = Image.open(os.path.join(edges_dir, "disk_soft4.png"))
        strip.resize((strip.width // 2, strip.height // 2), Image.LANCZOS).save(os.path.join(OUT, "edges.png"),
                                                                               optimize=True)
    print(f"wrote {OUT}/depth.png, {OUT}/layers.png, {OUT}/parallax.gif, {OUT}/edges.png")


if __name__ == "__main__":
    main()

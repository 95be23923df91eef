#!/usr/bin/python3
"""Writes the seed corpora of the fuzz targets (fuzz/corpus/<target>/seed-*): small valid
inputs of each format, so that libFuzzer starts from inputs that reach deep into each
parser instead of guessing magic numbers. Deterministic; run from anywhere with Debian's
python3 (numpy, PIL). Inputs that once crashed a target live beside the seeds as
crash-* files and are not touched here.
"""
import io
import json
import os

import numpy as np
from PIL import Image

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")


def write(target, name, data):
    folder = os.path.join(CORPUS, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "seed-" + name), "wb") as f:
        f.write(data)


def npy_bytes(array):
    out = io.BytesIO()
    np.save(out, array)
    return out.getvalue()


def image_bytes(image, fmt, **options):
    out = io.BytesIO()
    image.save(out, fmt, **options)
    return out.getvalue()


def gradient(width, height):
    x = np.arange(width)[None, :]
    y = np.arange(height)[:, None]
    return np.stack([(x * 16) % 256 + 0 * y, (y * 16) % 256 + 0 * x, (x + y) * 8 % 256], -1).astype(np.uint8)


def weight_file_seeds():
    with open(os.path.join(ROOT, "tests", "fixtures", "weights", "small.ampw"), "rb") as f:
        write("weight_file", "small.ampw", f.read())


def network_seeds():
    """The tiny depth and inpainting networks of the test fixtures (written by
    tests/fixtures/nets/make_loader_fixtures.py and training/export_inpaint.py)."""
    for name, path in (("tiny-depth.ampw", ("nets", "tiny_depth.ampw")), ("tiny-inpaint.ampw", ("inpaint", "tiny.ampw"))):
        with open(os.path.join(ROOT, "tests", "fixtures", *path), "rb") as f:
            write("networks", name, f.read())


def npy_seeds():
    source = os.path.join(ROOT, "tests", "weights_format", "npy")
    for name in sorted(os.listdir(source)):
        if name.endswith(".npy"):
            with open(os.path.join(source, name), "rb") as f:
                write("npy", name, f.read())


def mpi_json_seeds():
    # Describes the fuzz target's own two 4x3 layers (fuzz_mpi_json.cpp).
    planes = [{"depth": 10.0, "disparity": 40.0, "interval": [0, 128], "pixels": 6, "layer": "layer_00.png"},
              {"depth": 2.0, "disparity": 200.0, "interval": [128, 255], "pixels": 6, "layer": "layer_01.png"}]
    description = {"format": "ampi-mpi", "version": 1, "width": 4, "height": 3,
                   "camera": {"fx": 3.5, "fy": 3.5, "cx": 1.5, "cy": 1.0},
                   "near": 1.0, "far": 100.0, "plane_count": 2, "planes": planes}
    write("mpi_json", "two_planes.json", json.dumps(description, indent=2).encode())
    one = dict(description, plane_count=1, planes=planes[1:])
    write("mpi_json", "one_plane.json", json.dumps(one).encode())


def depth_map_seeds():
    # The first byte picks the file name (bits 0-1: png, npy, tiff, pgm) and bit 2 makes
    # the values distances (fuzz_depth_map.cpp).
    depth = (np.arange(24, dtype=np.float32).reshape(4, 6) + 1) / 4
    with open(os.path.join(ROOT, "tests", "fixtures", "slicing", "three_levels.png"), "rb") as f:
        write("depth_map", "png8", b"\x00" + f.read())
    png16 = Image.fromarray((depth * 1000).astype(np.uint16))
    write("depth_map", "png16", b"\x00" + image_bytes(png16, "PNG"))
    write("depth_map", "npy", b"\x01" + npy_bytes(depth))
    write("depth_map", "npy_distance", b"\x05" + npy_bytes(depth[None, :, :, None]))
    write("depth_map", "tiff_float", b"\x02" + image_bytes(Image.fromarray(depth, mode="F"), "TIFF"))
    write("depth_map", "pgm_distance", b"\x07" + image_bytes(Image.fromarray((depth * 10).astype(np.uint8)), "PPM"))


def photo_seeds():
    rgb = Image.fromarray(gradient(16, 16))
    write("photo", "rgb.png", image_bytes(rgb, "PNG"))
    write("photo", "gray16.png", image_bytes(Image.fromarray((gradient(16, 20)[:, :, 0].astype(np.uint16) * 250)), "PNG"))
    write("photo", "rgba.png", image_bytes(Image.fromarray(gradient(17, 16)).convert("RGBA"), "PNG"))
    write("photo", "baseline.jpg", image_bytes(rgb, "JPEG", quality=80))
    write("photo", "progressive.jpg", image_bytes(rgb, "JPEG", quality=60, progressive=True))
    exif = Image.Exif()
    exif[0x0112] = 6  # orientation: rotate 90 degrees clockwise to display
    write("photo", "exif_rotated.jpg", image_bytes(Image.fromarray(gradient(24, 16)), "JPEG", exif=exif.tobytes()))
    write("photo", "rgb.bmp", image_bytes(rgb, "BMP"))


def keyframes_seeds():
    frames = {"keyframes": [{"time": 0, "t": [0, 0, 0], "rotation": [0, 0, 0], "zoom": 1},
                            {"time": 1.5, "t": [0.1, -0.05, 0.2], "rotation": [2, -3, 1], "zoom": 1.2},
                            {"time": 3, "t": [0, 0, 0.4]}]}
    write("keyframes", "three.json", json.dumps(frames, indent=1).encode())
    write("keyframes", "one.json", b'{"keyframes": [{"time": 2, "zoom": 0.9}]}')


def main():
    for target in ("weight_file", "networks", "npy", "mpi_json", "depth_map", "photo", "keyframes"):
        folder = os.path.join(CORPUS, target)
        if os.path.isdir(folder):
            for name in os.listdir(folder):
                if name.startswith("seed-"):
                    os.remove(os.path.join(folder, name))
    weight_file_seeds()
    network_seeds()
    npy_seeds()
    mpi_json_seeds()
    depth_map_seeds()
    photo_seeds()
    keyframes_seeds()


if __name__ == "__main__":
    main()

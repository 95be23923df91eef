#!/usr/bin/env python3
"""WHDR of depth weight files on the ordinal photos as they are and mirrored left to right.

    /usr/bin/python3 training/mirror_whdr.py WEIGHTS.ampw... [--split val] [--split test]
        [--ordinal FILE] [--photos DIR]

Each photo is run as the engine runs it (pipeline/depth_estimate.cpp: the long side brought
to the file's working size by PIL's antialiased bilinear resize, the engine's tent filter;
edge-replicated to the network's multiple), once as it is and once mirrored, the mirrored
disparity mirrored back before the pairs are read. Every file was picked by its WHDR on `val` as the
photos are (train_depth.py --ordinal), never mirrored, so the gap between the two columns
on `val` and `test` is partly that choice; on photos no choice has seen it is the network's
own left-right bias alone. The subset of the ordinal set for the photos no bundled file
trained on: training/ordinal/pairs.py subset.
"""
import argparse
import sys
from pathlib import Path

import numpy as np
import torch
from PIL import Image

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "weights_format"))
import export_depth  # noqa: E402
import ordinal_data  # noqa: E402
import photo_folder  # noqa: E402
from ampw import read_ampw  # noqa: E402


def engine_input(photo, long_side: int):
    """(image [3, h, w] in [0, 1], points in its pixels): the full photo's long side
    brought to long_side, aspect kept, never enlarged (nets/depth_model.cpp). Unlike
    ordinal_data.validation_sample, whose resize takes PIL's reducing_gap shortcut, this is
    the exact tent filter the engine shrinks with (pipeline/tent_resize.h)."""
    height, width = photo.rgb.shape[:2]
    scale = min(1.0, long_side / max(height, width))
    size = (max(1, round(width * scale)), max(1, round(height * scale)))
    image = torch.from_numpy(np.asarray(Image.fromarray(photo.rgb).resize(size, Image.BILINEAR)).copy())
    points = (photo.points + 0.5) * np.array([size[0] / width, size[1] / height], np.float32) - 0.5
    return image.permute(2, 0, 1).float() / 255.0, torch.from_numpy(points)


def disparity_of(model, image: torch.Tensor, mirrored: bool) -> torch.Tensor:
    """The network's disparity [1, h, w] of image, mirrored in and back out when asked."""
    with torch.no_grad():
        disparity = ordinal_data.engine_disparity(model, image.flip(-1) if mirrored else image)
    return disparity.flip(-1) if mirrored else disparity


def whdr_both_ways(model, photos, long_side: int):
    """(WHDR as the photos are, WHDR mirrored, ordered pairs)."""
    wrong = [0.0, 0.0]
    pairs = 0
    for photo in photos:
        image, points = engine_input(photo, long_side)
        signs = torch.from_numpy(photo.signs)
        for i, mirrored in enumerate((False, True)):
            photo_wrong, photo_pairs = ordinal_data.whdr_counts(disparity_of(model, image, mirrored), points, signs)
            wrong[i] += photo_wrong
        pairs += photo_pairs
    return wrong[0] / max(pairs, 1), wrong[1] / max(pairs, 1), pairs


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("weights", nargs="+", help="depth weight files (.ampw)")
    ap.add_argument("--split", action="append", choices=ordinal_data.SPLITS,
                    help="repeatable (default val and test)")
    ap.add_argument("--ordinal", default=str(ordinal_data.ORDINAL_FILE), help="the ordinal set (default the merged one)")
    ap.add_argument("--photos", default=str(photo_folder.photo_root()),
                    help="the folder its photo names are relative to (default $AMPI_PHOTO_ROOT or ../shared/data/photos)")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args(argv)
    torch.set_num_threads(args.threads)
    ordinal_data.PHOTO_MAX_SIDE = 1 << 30  # the full photos, as `ampi eval depth` reads them
    splits = args.split or ["val", "test"]
    photos = {split: ordinal_data.load_split(split, Path(args.photos), Path(args.ordinal)) for split in splits}
    print("| weights | split | WHDR | mirrored | pairs |\n|---|---|---:|---:|---:|")
    for weights in args.weights:
        model = export_depth.import_ampw(weights)
        long_side = int(read_ampw(weights)[0]["depth.working_long_side"])
        for split in splits:
            as_is, mirrored, pairs = whdr_both_ways(model, photos[split], long_side)
            print(f"| {Path(weights).name} | {split} | {as_is:.4f} | {mirrored:.4f} | {pairs} |", flush=True)


if __name__ == "__main__":
    main()

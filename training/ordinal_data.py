"""Real photos with labelled point pairs (training/ordinal/ordinal.json.gz) for training and
validating the depth networks: the ranking loss and WHDR.

The ranking loss is Chen et al. 2016's ("Single-Image Depth Perception in the Wild") for
ordered pairs: log(1 + exp(-s (z_a - z_b))), s = +1 when A is nearer, on the predicted
disparity z (larger = nearer) read bilinearly at the two points. Pairs labelled too close
to call are left out here (the set keeps them). WHDR is the share of ordered pairs the
prediction orders wrongly, a tie counting half, as `ampi eval depth --ordinal` reports it.
"""
from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from PIL import Image, ImageOps

import distill
import photo_folder

ORDINAL_FILE = Path(__file__).resolve().parent / "ordinal" / "ordinal.json.gz"
SPLITS = ("train", "val", "test", "holdout")  # an ordinal set's photo entry's parts (training/ordinal/README.md)
PHOTO_MAX_SIDE = 640      # photos are kept decoded at this size (training crops are smaller)
CROP_SHARE = (0.7, 1.0)   # a training crop keeps this share of each side
WIDE_CROP_SHARE = (0.5, 1.0)  # train_depth.py --photo-augment: more zoom, more views of few photos


class OrdinalPhoto:
    def __init__(self, rgb: np.ndarray, points: np.ndarray, signs: np.ndarray, teacher=None):
        self.rgb = rgb          # H x W x 3 uint8, downscaled
        self.points = points    # P x 2 x 2: (a, b) x (x, y), in the downscaled pixels
        self.signs = signs      # P: +1 A nearer, -1 B nearer
        self.teacher = teacher  # H x W float32 disparity of a teacher's ensemble, or None


def validation_photos(photo_root: Path, ordinal_file: Path = ORDINAL_FILE) -> set:
    """Resolved paths of every photo of the validation split (its test part included) and
    of the holdout, labelled pairs or not: no other training data may show them
    (train_depth.py's distilled source leaves them out)."""
    entries = photo_folder.read_json(ordinal_file)["photos"]
    return {(Path(photo_root) / e["photo"]).resolve() for e in entries if e["split"] in ("val", "test", "holdout")}


def load_split(split: str, photo_root: Path, ordinal_file: Path = ORDINAL_FILE, teacher_labels=None):
    """The photos of one split ('train', 'val', 'test' or 'holdout') with their ordered pairs, and
    with teacher_labels (an `ampi distill` label folder of photo_root) each photo's label."""
    entries = photo_folder.read_json(ordinal_file)["photos"]
    teacher = TeacherLabels(teacher_labels, photo_root) if teacher_labels else None
    photos = []
    for entry in entries:
        if entry["split"] != split:
            continue
        pairs = [p for p in entry["pairs"] if p["label"] in ("A", "B")]
        if not pairs:
            continue
        path = Path(photo_root) / entry["photo"]
        if not path.is_file():
            raise RuntimeError(photo_folder.missing_photo(ordinal_file, entry["photo"], photo_root))
        with Image.open(path) as image:
            image = ImageOps.exif_transpose(image).convert("RGB")
        if image.size != (entry["width"], entry["height"]):
            raise RuntimeError(f"{entry['photo']}: is {image.size}, labelled at {entry['width']}x{entry['height']}")
        scale = min(1.0, PHOTO_MAX_SIDE / max(image.size))
        size = (round(image.width * scale), round(image.height * scale))
        rgb = np.asarray(image.resize(size, Image.BILINEAR, reducing_gap=2.0))
        points = np.array([[p["a"], p["b"]] for p in pairs], np.float32)
        points = (points + 0.5) * np.array([size[0] / image.width, size[1] / image.height], np.float32) - 0.5
        signs = np.array([1.0 if p["label"] == "A" else -1.0 for p in pairs], np.float32)
        photos.append(OrdinalPhoto(rgb, points, signs, teacher.of(entry["photo"], size) if teacher else None))
    if not photos:
        raise RuntimeError(f"{ordinal_file}: no labelled photos in split {split}")
    return photos


class TeacherLabels:
    """The labels of an `ampi distill` folder, looked up by photo name."""

    def __init__(self, folder, photo_root: Path):
        images, self.labels = distill.read_label_folder(folder)
        if images.resolve() != Path(photo_root).resolve():
            raise ValueError(f"{folder}: labels photos of {images}, not of {photo_root}")
        self.folder = folder

    def of(self, photo: str, size) -> np.ndarray:
        """The label of `photo` resized to size = (w, h)."""
        if photo not in self.labels:
            raise ValueError(f"{self.folder}: no label for {photo} (ampi distill labels every photo of its folder)")
        return _resize_map(distill.read_disparity(self.labels[photo]), size)


def _resize(rgb: np.ndarray, size):
    return np.array(Image.fromarray(rgb).resize(size, Image.BILINEAR, reducing_gap=2.0))


def _resize_map(disparity: np.ndarray, size):
    return np.array(Image.fromarray(disparity, mode="F").resize(size, Image.BILINEAR, reducing_gap=2.0))


def training_sample(photo: OrdinalPhoto, size, rng: random.Random, crop_share=CROP_SHARE):
    """A random crop (crop_share of each side), resized to size = (w, h), flipped half the
    time: (rgb [3, h, w] float in [0, 1], points [P, 2, 2] in its pixels, signs [P],
    the teacher's label [1, h, w] cropped alike or None). Pairs with a point outside the
    crop are dropped."""
    H, W = photo.rgb.shape[:2]
    cw, ch = round(W * rng.uniform(*crop_share)), round(H * rng.uniform(*crop_share))
    x0, y0 = rng.randint(0, W - cw), rng.randint(0, H - ch)
    rgb = _resize(photo.rgb[y0:y0 + ch, x0:x0 + cw], size)
    teacher = None if photo.teacher is None else _resize_map(photo.teacher[y0:y0 + ch, x0:x0 + cw], size)
    points = photo.points - np.array([x0, y0], np.float32)
    keep = ((points >= -0.5) & (points <= np.array([cw, ch], np.float32) - 0.5)).all(axis=(1, 2))
    points = (points[keep] + 0.5) * np.array([size[0] / cw, size[1] / ch], np.float32) - 0.5
    if rng.random() < 0.5:
        rgb = rgb[:, ::-1]
        teacher = None if teacher is None else teacher[:, ::-1]
        points[..., 0] = size[0] - 1 - points[..., 0]
    image = torch.from_numpy(np.ascontiguousarray(rgb)).permute(2, 0, 1).float() / 255.0
    if teacher is not None:
        teacher = torch.from_numpy(np.ascontiguousarray(teacher))[None]
    return image, torch.from_numpy(points), torch.from_numpy(photo.signs[keep]), teacher


def validation_sample(photo: OrdinalPhoto, long_side: int):
    """The whole photo as `ampi eval depth` gives it to the network: its long side brought
    to long_side (the weight file's working size), its aspect kept (nets/depth_model.cpp's
    depth_working_size), its pairs mapped along. The engine shrinks the full photo with the
    same tent filter (pipeline/tent_resize.h); this one starts from the photo kept at
    PHOTO_MAX_SIDE, and the two WHDRs agree within 0.1 point for the bundled lite on `val`
    and `test` (with OpenCV's area average, which the engine used before, the engine
    measured 0.8 and 1.1 points more)."""
    H, W = photo.rgb.shape[:2]
    scale = min(1.0, long_side / max(H, W))
    size = (max(1, round(W * scale)), max(1, round(H * scale)))
    rgb = _resize(photo.rgb, size)
    points = (photo.points + 0.5) * np.array([size[0] / W, size[1] / H], np.float32) - 0.5
    image = torch.from_numpy(np.ascontiguousarray(rgb)).permute(2, 0, 1).float() / 255.0
    return image, torch.from_numpy(points), torch.from_numpy(photo.signs)


def engine_disparity(model, image: torch.Tensor, device="cpu") -> torch.Tensor:
    """The network's disparity [1, h, w] of image [3, h, w], run as the engine runs it:
    edge-replicated to the network's multiple, the output cropped back (nets/depth_net.cpp)."""
    height, width = image.shape[-2:]
    padded = F.pad(image[None], (0, (-width) % model.multiple, 0, (-height) % model.multiple), mode="replicate")
    return model(padded.to(device).contiguous(memory_format=torch.channels_last))[-1][0, :, :height, :width]


def read_at(disparity: torch.Tensor, points: torch.Tensor) -> torch.Tensor:
    """disparity [1, H, W] read bilinearly at points [P, 2, 2] (pixel x, y): [P, 2]."""
    h, w = disparity.shape[-2:]
    grid = torch.stack([(points[..., 0] + 0.5) / w * 2 - 1, (points[..., 1] + 0.5) / h * 2 - 1], -1)
    return F.grid_sample(disparity[None], grid[None], mode="bilinear", padding_mode="border",
                         align_corners=False)[0, 0]


def ranking_loss(disparity: torch.Tensor, pairs) -> torch.Tensor:
    """Mean log(1 + exp(-s (z_a - z_b))) over every pair of the batch. disparity
    [N, 1, H, W]; pairs: N (points, signs) tuples."""
    terms = []
    for z, (points, signs) in zip(disparity, pairs):
        if len(signs):
            values = read_at(z, points)
            terms.append(F.softplus(-signs * (values[:, 0] - values[:, 1])))
    return torch.cat(terms).mean() if terms else disparity.new_zeros(())


def whdr_counts(disparity: torch.Tensor, points: torch.Tensor, signs: torch.Tensor):
    """(wrong, pairs) of one map [1, H, W]; a tie counts half."""
    values = read_at(disparity, points)
    predicted = torch.sign(values[:, 0] - values[:, 1])
    wrong = torch.where(predicted == 0, torch.full_like(signs, 0.5), (predicted != signs).float())
    return float(wrong.sum()), int(len(signs))


def labels_whdr(labels, split: str, photo_root: Path, ordinal_file: Path = ORDINAL_FILE):
    """(WHDR, ordered pairs) of an `ampi distill` label folder's labels on one split: how
    well a teacher's ensemble orders the pairs before any network learns from it."""
    wrong, pairs = 0.0, 0
    for photo in load_split(split, photo_root, ordinal_file, labels):
        photo_wrong, photo_pairs = whdr_counts(torch.from_numpy(photo.teacher)[None],
                                               torch.from_numpy(photo.points), torch.from_numpy(photo.signs))
        wrong, pairs = wrong + photo_wrong, pairs + photo_pairs
    return wrong / max(pairs, 1), pairs


def main(argv=None):
    import argparse
    p = argparse.ArgumentParser(description="WHDR of an `ampi distill` label folder on the ordinal set: "
                                            "/usr/bin/python3 training/ordinal_data.py LABELS [--split test]")
    p.add_argument("labels", help="an ampi distill label folder of the photo folder")
    p.add_argument("--split", default="val", choices=SPLITS)
    p.add_argument("--ordinal", default=str(ORDINAL_FILE))
    args = p.parse_args(argv)
    whdr, pairs = labels_whdr(args.labels, args.split, photo_folder.photo_root(), args.ordinal)
    print(f"{args.labels}: WHDR {whdr:.4f} on {pairs} ordered pairs of {args.split}")


if __name__ == "__main__":
    main()

"""A small procedural RGB-D source: photo-textured cards standing on a ground plane.

The small built-in data source of train_depth.py (`--data cards`), enough to give a
network real structure; the procedural scenes of training/scenes.py (`--data scenes`, the
default) are the richer source.

Scene, for a pinhole camera at height 1 looking horizontally (horizon at row `horizon`):
  - the ground plane below the horizon: a pixel r rows under it sees depth f / (r + 0.5),
    so its disparity grows linearly with r: the ground recedes towards the horizon;
  - above the horizon, sky (disparity 0) or a back wall at a far depth;
  - 2 to 7 cards (rectangles or ellipses) standing on the ground at random depths, drawn
    far to near so nearer cards occlude farther ones; a card at depth z has its base on
    the ground row of depth z and a constant disparity f / z.
Textures are random crops of the photos in ../shared/data/photos (all but every tenth,
which stays for validation), shaded darker with distance and with a haze towards far.
Every value is exact and the scene is a pure function of its seed.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

PHOTO_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "photos"
TEXTURE_SIDE = 256  # photos are cached as squares of this side


def _photo_paths(root: Path):
    return sorted(p for p in root.rglob("*") if p.suffix.lower() in (".jpg", ".jpeg", ".png"))


class TextureBank:
    """Training photos (every tenth by sorted name is left out), decoded once, small."""

    def __init__(self, root: Path = PHOTO_ROOT):
        from PIL import Image  # Debian's python3-pil
        paths = [p for i, p in enumerate(_photo_paths(root)) if i % 10]
        if not paths:
            raise FileNotFoundError(f"{root}: no photos to texture the scenes with")
        self.images = [np.asarray(Image.open(p).convert("RGB").resize((TEXTURE_SIDE, TEXTURE_SIDE)),
                                  dtype=np.float32) / 255.0 for p in paths]

    def patch(self, rng: np.random.Generator, height: int, width: int) -> np.ndarray:
        """A height x width texture: a random photo's crop, stretched by nearest sampling."""
        image = self.images[rng.integers(len(self.images))]
        side = int(rng.integers(TEXTURE_SIDE // 4, TEXTURE_SIDE + 1))
        y0, x0 = rng.integers(0, TEXTURE_SIDE - side + 1, size=2)
        rows = y0 + (np.arange(height) * side // max(height, 1))
        cols = x0 + (np.arange(width) * side // max(width, 1))
        return image[rows][:, cols]


def _ground_disparity(height: int, horizon: int, focal: float) -> np.ndarray:
    rows = np.arange(height, dtype=np.float32)
    return np.where(rows >= horizon, (rows - horizon + 0.5) / focal, 0.0).astype(np.float32)


def _ground_texture(rng, bank, height, width, horizon, focal):
    """A photo tiled on the ground plane in perspective: the texture shrinks and
    compresses towards the horizon, the depth cue a photo's ground gives."""
    image = bank.images[rng.integers(len(bank.images))]
    tile = rng.uniform(1.0, 6.0)  # metres one texture repeat covers
    rows = np.arange(horizon, height, dtype=np.float32) - horizon + 0.5
    z = (focal / rows)[:, None]  # camera height 1
    x = (np.arange(width, dtype=np.float32)[None, :] - width / 2) * z / focal
    u = ((x / tile) * TEXTURE_SIDE).astype(np.int64) % TEXTURE_SIDE
    v = ((z / tile) * TEXTURE_SIDE).astype(np.int64) % TEXTURE_SIDE
    return image[np.broadcast_to(v, u.shape), u]


def render(seed: int, width: int, height: int, bank: TextureBank):
    """(rgb float32 H x W x 3 in [0, 1], disparity float32 H x W; larger = nearer)."""
    rng = np.random.default_rng(seed)
    focal = width * rng.uniform(0.6, 1.2)
    horizon = int(height * rng.uniform(0.25, 0.6))
    rgb = np.empty((height, width, 3), np.float32)
    disparity = np.zeros((height, width), np.float32)

    ground_rows = _ground_disparity(height, horizon, focal)
    disparity[horizon:] = ground_rows[horizon:, None]
    rgb[horizon:] = _ground_texture(rng, bank, height, width, horizon, focal)
    if rng.random() < 0.5:  # sky: a smooth colour gradient, infinitely far
        top, bottom = rng.uniform(0.3, 1.0, 3), rng.uniform(0.6, 1.0, 3)
        t = np.linspace(0.0, 1.0, horizon, dtype=np.float32)[:, None, None]
        rgb[:horizon] = top * (1 - t) + bottom * t
    else:  # a far wall standing on the horizon's ground
        rgb[:horizon] = bank.patch(rng, horizon, width)
        disparity[:horizon] = 1.0 / rng.uniform(40.0, 80.0)

    cards = []
    for _ in range(int(rng.integers(2, 8))):
        depth = rng.uniform(1.5, 30.0)
        cards.append(depth)
    for depth in sorted(cards, reverse=True):  # far to near: nearer cards occlude
        _draw_card(rgb, disparity, rng, bank, depth, focal, horizon)

    haze = rng.uniform(0.0, 0.4)
    fog = (haze * np.exp(-20.0 * disparity))[..., None]  # thicker with distance, full on sky
    rgb = rgb * (1 - fog) + fog * rng.uniform(0.6, 0.9)
    rgb = rgb * rng.uniform(0.7, 1.2) + rng.uniform(-0.05, 0.05)
    return np.clip(rgb, 0.0, 1.0).astype(np.float32), disparity


def _draw_card(rgb, disparity, rng, bank, depth, focal, horizon):
    height, width = disparity.shape
    base = int(round(horizon + focal / depth - 0.5))  # the ground row at this depth
    card_h = int(focal * rng.uniform(0.3, 2.5) / depth)
    card_w = int(focal * rng.uniform(0.2, 1.5) / depth)
    if card_h < 2 or card_w < 2:
        return
    x0 = int(rng.integers(-card_w // 2, width - card_w // 2))
    top = base - card_h
    ys, xs = np.mgrid[top:base, x0:x0 + card_w]
    inside = (ys >= 0) & (ys < height) & (xs >= 0) & (xs < width)
    if rng.random() < 0.4:  # an ellipse cut-out instead of a rectangle
        cy, cx = (top + base) / 2, x0 + card_w / 2
        inside &= ((ys - cy) / (card_h / 2)) ** 2 + ((xs - cx) / (card_w / 2)) ** 2 <= 1.0
    if not inside.any():
        return
    texture = bank.patch(rng, card_h, card_w) * rng.uniform(0.6, 1.1)
    rgb[ys[inside], xs[inside]] = texture[inside]
    disparity[ys[inside], xs[inside]] = 1.0 / depth


class CardScenes:
    """Scenes by seed at a fixed size; the source train_depth.py calls."""

    def __init__(self, width: int, height: int):
        self.width, self.height = width, height
        self.bank = TextureBank()

    def __call__(self, seed: int):
        return render(seed, self.width, self.height, self.bank)

"""Training data for the inpainting network, made from single photos as in the paper
(section "Multiplane image inpainting"):

  1. slice the photo's disparity map into planes (the adaptive histogram slicing);
  2. take plane j together with every plane behind it: the region U_j of all pixels
     farther than a disparity threshold (j is never the nearest plane, whose U is the
     whole photo);
  3. erode U_j with a 3x3 element k times, which removes a border of about k pixels
     along the contours of the nearer planes (the photo's own edges are not eroded);
  4. the network sees the photo inside the eroded region and a hole mask elsewhere,
     and is supervised with the original photo on the removed border (the only hole
     pixels whose true background colour is known).

Split: the photos under the root sorted by relative path; every tenth (indices 9, 19,
...) is validation and never trained on.

Disparity: 16-bit PNGs (larger = nearer) from our depth network, one per photo under
DISPARITY_DIR/<relative path>.png, written by `python3 training/inpaint_data.py
--write-disparity --ampi build-i/ampi`. A photo without one gets the stand-in of
`standin_disparity` (documented in training/INPAINT.md): a smooth blend of a vertical ramp
and of blurred colour, so layer contours follow image edges as real depth edges do.
A plane map under PLANES_DIR/<relative path>.png (written by `write_planes`: what
training/gpu_run.py carries to a GPU machine) replaces both: the photo's slicing done
ahead, at the photo's size.

Slicing here is a numpy port of the paper's transition selection (slicing/adaptive.h:
eps 0.001, xi 8, threshold 0.1, at most 8 planes), with a box blur and a gradient-magnitude
edge band standing in for the bilateral filter and Canny (no OpenCV in this Python).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import zlib
from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F
from PIL import Image, ImageOps

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from inpaint_model import PREFILL  # noqa: E402
from inpaint_push_pull import PREFILLS  # noqa: E402

PHOTO_EXTENSIONS = (".jpg", ".jpeg", ".png")
DEFAULT_PHOTOS = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data", "photos")
DEFAULT_DISPARITY_DIR = os.path.join(os.path.dirname(__file__), "data_cache", "inpaint_disparity")
VALIDATION_EVERY = 10
MAX_SIDE = 768  # photos are kept at most this large (the long side), like a 1024x768 MPI
ERODE_RANGE = (8, 40)  # training erosion iterations; the inference margin is 40 px
MIN_REMOVED, MIN_KNOWN = 0.02, 0.25  # fractions of a crop a sample needs

# transition selection, as slicing/adaptive.h's paper slicer with its plane guard at 0.5
# (`ampi slice --slicer paper --min-plane-share 0.5`): the slicing the bundled inpainting
# network trained on. ampi's default slicer differs: it keeps the paper's plane count but
# places the cuts by dynamic programming (slicing/optimal_cuts.h), with no guard.
SLICE_EPS, SLICE_XI, SLICE_THRESHOLD, SLICE_MAX_PLANES = 0.001, 8, 0.1, 8
SLICE_MIN_PLANE_SHARE = 0.5  # each plane > 0.5 / 8 of h
EDGE_GRADIENT, EDGE_BAND = 6.0, 7  # levels per pixel that make an edge; band width


# ---- photos and the split -----------------------------------------------------------------

def list_photos(root: str):
    """Relative paths of every photo under root, sorted."""
    found = []
    for dirpath, _dirs, files in os.walk(root):
        for f in files:
            if f.lower().endswith(PHOTO_EXTENSIONS):
                found.append(os.path.relpath(os.path.join(dirpath, f), root))
    if not found:
        raise FileNotFoundError(f"{root}: no photos")
    return sorted(found)


def split_photos(paths):
    """(train, validation): every tenth path by sorted order is validation."""
    val = [p for i, p in enumerate(paths) if i % VALIDATION_EVERY == VALIDATION_EVERY - 1]
    train = [p for i, p in enumerate(paths) if i % VALIDATION_EVERY != VALIDATION_EVERY - 1]
    return train, val


def load_photo(path: str, max_side: int = MAX_SIDE) -> np.ndarray:
    """uint8 RGB [H, W, 3], EXIF orientation applied, the long side at most max_side."""
    with Image.open(path) as im:
        im = ImageOps.exif_transpose(im).convert("RGB")
        scale = max_side / max(im.size)
        if scale < 1:
            im = im.resize((round(im.width * scale), round(im.height * scale)), Image.BICUBIC)
        return np.asarray(im, dtype=np.uint8).copy()


def box_blur(x: np.ndarray, radius: int) -> np.ndarray:
    """Mean over a (2r+1)-square, edges replicated; x is [H, W] float."""
    t = torch.from_numpy(np.ascontiguousarray(x, dtype=np.float32))[None, None]
    t = F.pad(t, (radius,) * 4, mode="replicate")
    return F.avg_pool2d(t, 2 * radius + 1, stride=1)[0, 0].numpy()


def standin_disparity(rgb: np.ndarray, seed: int) -> np.ndarray:
    """Until our depth network's map exists: nearer at the bottom (a ground plane), plus a
    blurred random blend of the colour channels so that contours follow image edges."""
    rng = np.random.default_rng(seed)
    h, w, _ = rgb.shape
    colour = rgb.astype(np.float32) / 255.0 @ rng.uniform(-1, 1, 3).astype(np.float32)
    colour = box_blur(box_blur(colour, 4), 4)
    colour = (colour - colour.mean()) / max(float(colour.std()), 1e-3)
    ramp = np.linspace(0, 1, h, dtype=np.float32)[:, None].repeat(w, axis=1)
    return ramp + rng.uniform(0.15, 0.4) * colour


def disparity_path(disparity_dir: str, rel: str) -> str:
    return os.path.join(disparity_dir, rel + ".png")


def load_disparity(path: str, size) -> np.ndarray:
    """A 16-bit disparity PNG as float32 [H, W], resized bilinearly to size (w, h)."""
    with Image.open(path) as im:
        d = np.asarray(im, dtype=np.float32)
    if d.ndim != 2:
        raise ValueError(f"{path}: expected a single-channel disparity PNG")
    if d.shape[::-1] != tuple(size):
        d = np.asarray(Image.fromarray(d, mode="F").resize(size, Image.BILINEAR), dtype=np.float32)
    return d


# ---- slicing ------------------------------------------------------------------------------

def normalise_levels(disparity: np.ndarray) -> np.ndarray:
    lo, hi = float(disparity.min()), float(disparity.max())
    if hi <= lo:
        return np.zeros(disparity.shape, np.uint8)
    return np.rint((disparity - lo) * (255.0 / (hi - lo))).astype(np.uint8)


def slicing_histogram(levels: np.ndarray) -> np.ndarray:
    """Normalised histogram of the smoothed levels, the band around depth edges left out."""
    smooth = box_blur(levels.astype(np.float32), 2)
    gy, gx = np.gradient(smooth)
    edges = (np.abs(gx) + np.abs(gy)) > EDGE_GRADIENT
    band = box_blur(edges.astype(np.float32), EDGE_BAND // 2) > 0
    keep = smooth[~band] if (~band).any() else smooth.ravel()
    h = np.bincount(np.clip(np.rint(keep), 0, 255).astype(np.int64), minlength=256).astype(np.float64)
    return h / h.sum()


def select_transitions(h: np.ndarray) -> list:
    """The paper's greedy choice on t = laplacian(h) / max(eps, h), with the C++ slicer's
    guard (slicing/adaptive.h select_transitions) at SLICE_MIN_PLANE_SHARE: a candidate
    that would leave a plane with that share / max_planes of h or less on either side is
    dropped."""
    lap = np.zeros_like(h)
    lap[1:-1] = h[:-2] - 2 * h[1:-1] + h[2:]
    t = lap / np.maximum(SLICE_EPS, h)
    t[0] = t[-1] = 0
    prefix = np.concatenate([[0.0], np.cumsum(h)])
    min_mass = SLICE_MIN_PLANE_SHARE / SLICE_MAX_PLANES
    bounds = [0, len(h)]  # interval ends; the top interval holds the last bin
    chosen = []
    while len(chosen) < SLICE_MAX_PLANES - 1:
        i = int(np.argmax(t))
        if t[i] <= SLICE_THRESHOLD:
            break
        above = next(b for b in bounds if b > i)
        below = max(b for b in bounds if b <= i)
        if prefix[i] - prefix[below] > min_mass and prefix[above] - prefix[i] > min_mass:
            chosen.append(i)
            bounds = sorted(bounds + [i])
            t[max(0, i - SLICE_XI):i + SLICE_XI + 1] = 0
        else:
            t[i] = 0
    return sorted(chosen)


def slice_labels(disparity: np.ndarray) -> np.ndarray:
    """Plane index per pixel, 0 = farthest; planes that hold no pixel are dropped."""
    levels = normalise_levels(disparity)
    bounds = select_transitions(slicing_histogram(levels))
    labels = np.digitize(levels, bounds).astype(np.int32)
    _, dense = np.unique(labels, return_inverse=True)
    return dense.reshape(levels.shape).astype(np.uint8)


# ---- samples ------------------------------------------------------------------------------

@dataclass
class Photo:
    name: str
    rgb: np.ndarray     # uint8 [H, W, 3]
    labels: np.ndarray  # uint8 [H, W], plane index, 0 = farthest
    planes: int


def standin_seed(rel: str) -> int:
    """Fixed per photo, so the stand-in a photo gets never depends on the list it is in."""
    return zlib.crc32(rel.encode("utf-8"))


def photo_disparity(root: str, rel: str, disparity_dir: str, rgb: np.ndarray) -> np.ndarray:
    dpath = disparity_path(disparity_dir, rel)
    if os.path.exists(dpath):
        return load_disparity(dpath, (rgb.shape[1], rgb.shape[0]))
    return standin_disparity(rgb, standin_seed(rel))


def write_planes(disparity_file: str, size, out: str):
    """The plane map that prepare_photo slices from a cached disparity map for a photo of
    size (w, h), as an 8-bit PNG: what crosses to a GPU machine instead of the map (a few
    KB of plane indices compress far better than the map's smooth levels)."""
    labels = slice_labels(load_disparity(disparity_file, size))
    os.makedirs(os.path.dirname(out), exist_ok=True)
    Image.fromarray(labels).save(out, optimize=True)


def load_planes(path: str, shape) -> np.ndarray:
    """A plane map of write_planes for a photo of shape (h, w)."""
    with Image.open(path) as im:
        labels = np.asarray(im, dtype=np.uint8)
    if labels.shape != tuple(shape):
        raise ValueError(f"{path}: a {labels.shape[1]}x{labels.shape[0]} plane map for a "
                         f"{shape[1]}x{shape[0]} photo")
    return labels


def planes_file(planes_dir: str | None, rel: str) -> str | None:
    """The photo's plane map under planes_dir (laid out as the disparity cache), if any."""
    path = disparity_path(planes_dir, rel) if planes_dir else None
    return path if path and os.path.exists(path) else None


def has_depth(rel: str, disparity_dir: str, planes_dir: str | None) -> bool:
    """Whether the photo is sliced by our depth network (its plane map or a cached
    disparity map), not by the stand-in."""
    return planes_file(planes_dir, rel) is not None or os.path.exists(disparity_path(disparity_dir, rel))


def prepare_photo(root: str, rel: str, disparity_dir: str, planes_dir: str | None = None) -> Photo:
    rgb = load_photo(os.path.join(root, rel))
    planes = planes_file(planes_dir, rel)
    if planes:
        labels = load_planes(planes, rgb.shape[:2])
    else:
        labels = slice_labels(photo_disparity(root, rel, disparity_dir, rgb))
    return Photo(rel, rgb, labels, int(labels.max()) + 1)


def erode(mask: torch.Tensor, iterations: int) -> torch.Tensor:
    """k iterations of a 3x3 erosion = one (2k+1)-square erosion, as two 1-D min passes.
    Outside the tensor counts as inside the mask (OpenCV's default), so the photo's own
    border is not eroded. mask: [..., H, W] float in {0, 1}."""
    side = 2 * iterations + 1
    inv = 1.0 - mask.reshape(-1, 1, *mask.shape[-2:])
    inv = F.max_pool2d(inv, (1, side), stride=1, padding=(0, iterations))
    inv = F.max_pool2d(inv, (side, 1), stride=1, padding=(iterations, 0))
    return (1.0 - inv).reshape(mask.shape)


def contour_pixels(region: np.ndarray) -> np.ndarray:
    """(y, x) of region pixels with a 4-neighbour outside it (inside the photo)."""
    r = region
    edge = np.zeros_like(r)
    edge[1:, :] |= r[1:, :] & ~r[:-1, :]
    edge[:-1, :] |= r[:-1, :] & ~r[1:, :]
    edge[:, 1:] |= r[:, 1:] & ~r[:, :-1]
    edge[:, :-1] |= r[:, :-1] & ~r[:, 1:]
    return np.argwhere(edge)


def make_sample(photo: Photo, rng: np.random.Generator, crop: int, erode_iterations: int):
    """One training example as float tensors (rgb [3, c, c] in [-1, 1], hole [1, c, c],
    removed [1, c, c], prefilled [3, c, c]: rgb with every hole pixel replaced by the 8-bit
    PREFILL fill from the known ones, what the C++ filler feeds the network), or None
    when this draw has nothing to inpaint."""
    h, w = photo.labels.shape
    if photo.planes < 2 or h < crop or w < crop:
        return None
    j = int(rng.integers(0, photo.planes - 1))
    region = photo.labels <= j
    contour = contour_pixels(region)
    if len(contour) == 0:
        return None
    cy, cx = contour[rng.integers(len(contour))]
    y0 = int(np.clip(cy - crop // 2 + rng.integers(-crop // 4, crop // 4 + 1), 0, h - crop))
    x0 = int(np.clip(cx - crop // 2 + rng.integers(-crop // 4, crop // 4 + 1), 0, w - crop))
    # erode on the crop plus a margin of k, so the crop's erosion is exact
    k = erode_iterations
    ya, yb, xa, xb = max(0, y0 - k), min(h, y0 + crop + k), max(0, x0 - k), min(w, x0 + crop + k)
    window = torch.from_numpy(region[ya:yb, xa:xb].astype(np.float32))
    # erode() treats outside as inside: right at the photo's border, that is its meaning;
    # on a window side cut inside the photo, the margin of k keeps the crop exact.
    eroded = erode(window, k)[y0 - ya:y0 - ya + crop, x0 - xa:x0 - xa + crop]
    inside = torch.from_numpy(region[y0:y0 + crop, x0:x0 + crop].astype(np.float32))
    removed = inside * (1.0 - eroded)
    # a hole with (almost) no known context around it teaches nothing about the margins
    if removed.mean() < MIN_REMOVED or eroded.mean() < MIN_KNOWN:
        return None
    image = photo.rgb[y0:y0 + crop, x0:x0 + crop]
    hole = 1.0 - eroded
    if rng.random() < 0.5:
        image, hole, removed = image[:, ::-1], hole.flip(-1), removed.flip(-1)
    image = np.ascontiguousarray(image)
    known = hole.numpy() < 0.5
    prefilled = PREFILLS[PREFILL](image, known, ~known)
    as_tensor = lambda a: torch.from_numpy(a).permute(2, 0, 1).float() / 127.5 - 1.0  # noqa: E731
    return as_tensor(image), hole[None], removed[None], as_tensor(prefilled)


class SampleSource:
    """Draws batches of examples from a list of prepared photos."""

    def __init__(self, photos, crop: int, erode_range=ERODE_RANGE):
        self.photos = [p for p in photos if p.planes >= 2]
        if not self.photos:
            raise ValueError("no photo slices into two planes or more")
        self.crop = crop
        self.erode_range = erode_range

    def sample(self, rng: np.random.Generator):
        while True:
            photo = self.photos[rng.integers(len(self.photos))]
            k = int(rng.integers(self.erode_range[0], self.erode_range[1] + 1))
            s = make_sample(photo, rng, self.crop, k)
            if s is not None:
                return s

    def batch(self, rng: np.random.Generator, size: int):
        """(rgb, hole, removed, prefilled), each stacked on a new first axis."""
        return tuple(torch.stack(t) for t in zip(*(self.sample(rng) for _ in range(size))))


def prepare_photos(root: str, rels, disparity_dir: str, log=print, standin_too: bool = False,
                   planes_dir: str | None = None):
    """One Photo per path, sliced with its plane map or cached disparity (the stand-in
    without either); standin_too adds a second Photo sliced with the stand-in where the
    photo has depth, so the network sees both kinds of plane contours."""
    photos, standins = [], 0
    for rel in rels:
        photos.append(prepare_photo(root, rel, disparity_dir, planes_dir))
        cached = has_depth(rel, disparity_dir, planes_dir)
        standins += not cached
        if standin_too and cached:
            rgb = photos[-1].rgb
            labels = slice_labels(standin_disparity(rgb, standin_seed(rel)))
            photos.append(Photo(rel + "#standin", rgb, labels, int(labels.max()) + 1))
            standins += 1
    log(f"prepared {len(photos)} sliced photos from {len(rels)} ({standins} with the stand-in "
        f"disparity), {sum(p.planes for p in photos) / len(photos):.1f} planes on average")
    return photos


# ---- disparity from our depth network -------------------------------------------------------

def write_disparity(root: str, disparity_dir: str, ampi: str, model: str):
    """Runs `ampi depth` on every photo (train and validation: the depth network is not
    the model being validated) and stores the maps where prepare_photo finds them."""
    for rel in list_photos(root):
        out = disparity_path(disparity_dir, rel)
        if os.path.exists(out):
            continue
        os.makedirs(os.path.dirname(out), exist_ok=True)
        tmp = out + ".tmp.png"
        subprocess.run([ampi, "depth", os.path.join(root, rel), "-o", tmp, "--model", model], check=True)
        os.replace(tmp, out)
        print(f"{rel}: disparity written", flush=True)


def write_standin(root: str, out_dir: str):
    """The stand-in disparity of every photo as a 16-bit PNG (larger = nearer), laid out as
    the disparity cache, for `ampi eval inpaint --depth-dir` to evaluate on the same kind
    of planes the network trained on."""
    for rel in list_photos(root):
        rgb = load_photo(os.path.join(root, rel))
        d = standin_disparity(rgb, standin_seed(rel))
        d16 = np.rint((d - d.min()) / max(float(d.max() - d.min()), 1e-6) * 65535).astype(np.uint16)
        out = disparity_path(out_dir, rel)
        os.makedirs(os.path.dirname(out), exist_ok=True)
        Image.fromarray(d16).save(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--photos", default=DEFAULT_PHOTOS)
    ap.add_argument("--disparity-dir", default=DEFAULT_DISPARITY_DIR)
    ap.add_argument("--write-disparity", action="store_true", help="run `ampi depth` on every photo")
    ap.add_argument("--ampi", default="build/ampi", help="the ampi program for --write-disparity")
    ap.add_argument("--model", default="lite", help="depth model for --write-disparity")
    ap.add_argument("--link-validation", metavar="DIR",
                    help="fill DIR with links to the validation photos (for ampi eval inpaint)")
    ap.add_argument("--write-standin", metavar="DIR", help="write every photo's stand-in disparity")
    args = ap.parse_args(argv)
    if args.write_standin:
        write_standin(args.photos, args.write_standin)
        return 0
    if args.write_disparity:
        write_disparity(args.photos, args.disparity_dir, args.ampi, args.model)
        return 0
    train, val = split_photos(list_photos(args.photos))
    if args.link_validation:
        for rel in val:
            link = os.path.join(args.link_validation, rel)
            os.makedirs(os.path.dirname(link), exist_ok=True)
            if not os.path.lexists(link):
                os.symlink(os.path.abspath(os.path.join(args.photos, rel)), link)
    print(f"{len(train)} training photos, {len(val)} validation photos: {', '.join(val)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

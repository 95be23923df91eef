"""The photo folder and its fixed train/validation splits.

The photos (../shared/data/photos, or $AMPI_PHOTO_ROOT) are never copied into the
repository. Splits go by a photo's place in its folder's sorted names, so that a copy of
the folder with the same names (gpu_run.py's downscaled one) splits the same way: every
tenth photo is validation (photo_split), every fifth is the real-photo ordinal validation
(ordinal_split, a superset of the former). Every second of the archive photos labelled
last is the ordinal set's 'holdout' part (HOLDOUT_GROUPS). Scene seeds split too
(is_validation_seed): validation scenes are textured only with validation photos.
"""

import functools
import gzip
import json
import os
from pathlib import Path

import numpy as np
from PIL import Image

PHOTO_SUFFIXES = {'.jpg', '.jpeg', '.png'}
DEFAULT_PHOTO_ROOT = Path(__file__).resolve().parents[2] / 'shared' / 'data' / 'photos'
VALIDATION_SEED_START = 10 ** 9
VALIDATION_PHOTO_PERIOD = 10      # every tenth photo of a folder (by sorted name) is validation
ORDINAL_VALIDATION_PERIOD = 5     # every fifth: the real-photo ordinal validation (training/ordinal)
# Folders with no validation photos: training/archive_photos.py's, added after the splits
# were fixed, so that validation and test stay the photos they were. Their photos train,
# but for the holdout below.
ARCHIVE_FOLDER = 'archive'
NO_VALIDATION_FOLDERS = {ARCHIVE_FOLDER}
# Archive photos added after every bundled network had been trained and picked, in two
# groups (plasma-workspace-wallpapers', mate-backgrounds' and gcompris-qt-data's; then the
# photos of twelve documentation, game and theme packages): no pick has seen them, unlike
# the val/test photos, picked on round after round. Every second photo of each group, by
# sorted name among that group's photos, is the 'holdout' part of the ordinal set: never
# trained on, never picked on, scored only to judge a pick. The other half trains. A new
# group counts on its own, so the photos of the groups before it keep their parts.
HOLDOUT_GROUPS = (
    ('gcompris_', 'mate_', 'plasma_'),
    ('digikam_', 'gimphelp_', 'hugin_', 'jigsaw_', 'kphotoalbum_', 'lxqt_', 'palapeli_', 'scribus_',
     'sddm_maldives_', 'sklearn_', 'tuxpaint_', 'tuxtype_'),
)
HOLDOUT_PERIOD = 2


def is_validation_seed(seed):
    """Seeds from 10**9 up are the fixed synthetic validation set, never trained on."""
    return seed >= VALIDATION_SEED_START


@functools.lru_cache(maxsize=None)
def _photo_names(folder):
    try:
        entries = list(Path(folder).iterdir())
    except OSError as error:
        raise RuntimeError(f'{folder}: cannot list photos ({error.strerror})') from error
    return tuple(sorted(p.name for p in entries if p.suffix.lower() in PHOTO_SUFFIXES))


def _every_nth_of_folder(path, period, prefixes=('',)):
    """True for every period-th photo of its folder by sorted name (indices period - 1,
    2 period - 1, ...), counted among the photos whose names start with one of prefixes."""
    path = Path(path)
    names = [n for n in _photo_names(str(path.resolve().parent)) if n.startswith(prefixes)]
    if path.name not in names:
        raise ValueError(f'{path}: not a photo (.jpg, .jpeg, .png) in its folder')
    return names.index(path.name) % period == period - 1


def _without_validation(path):
    return Path(path).parent.name in NO_VALIDATION_FOLDERS


def _holdout(path):
    """True for every HOLDOUT_PERIOD-th archive photo of a HOLDOUT_GROUPS group, counted
    among that group's photos by sorted name."""
    return any(Path(path).name.startswith(group) and _every_nth_of_folder(path, HOLDOUT_PERIOD, group)
               for group in HOLDOUT_GROUPS)


def photo_split(path):
    """'val' for every tenth photo of its folder by sorted name, else 'train'."""
    if _without_validation(path):
        return 'train'
    return 'val' if _every_nth_of_folder(path, VALIDATION_PHOTO_PERIOD) else 'train'


def ordinal_split(path):
    """'val' for every fifth photo of its folder by sorted name (the synthetic validation
    photos and as many more), else 'train'. Ordinal validation photos are never trained on:
    not ranked, and not textures of training scenes either. Archive photos are 'train'
    but for the 'holdout' half of those labelled last, kept out of training the same way."""
    if _without_validation(path):
        return 'holdout' if _holdout(path) else 'train'
    return 'val' if _every_nth_of_folder(path, ORDINAL_VALIDATION_PERIOD) else 'train'


def photo_root():
    # an empty AMPI_PHOTO_ROOT (`export AMPI_PHOTO_ROOT=`) is unset, not the current folder
    return Path(os.environ.get('AMPI_PHOTO_ROOT') or DEFAULT_PHOTO_ROOT)


def read_json(path):
    """A JSON file of photo names and points (the pair file, an ordinal set), gzip-compressed
    when its name ends in .gz: the bundled ones are, since they travel to GPU machines with
    the working tree against a transfer limit."""
    data = Path(path).read_bytes()
    return json.loads(gzip.decompress(data) if Path(path).suffix == '.gz' else data)


def missing_photo(source, photo, root):
    """The one-line error for a photo that source names and root lacks: for an archive
    photo, how to make the root that holds it."""
    hint = ''
    if Path(photo).parent.name in NO_VALIDATION_FOLDERS:
        hint = (' (the archive photos: run training/archive_photos.py and set '
                'AMPI_PHOTO_ROOT=training/data_cache/photos)')
    return f'{source}: {photo} is not under {root}{hint}'


def image_files(root):
    """Every photo under root, sorted, linked folders followed (training/archive_photos.py's
    root links ../shared's folders)."""
    return sorted(Path(folder) / name for folder, _subfolders, names in os.walk(root, followlinks=True)
                  for name in names if Path(name).suffix.lower() in PHOTO_SUFFIXES)


def list_photos(split=None, root=None):
    """Sorted photo paths under root (default: $AMPI_PHOTO_ROOT or ../shared/data/photos)."""
    root = Path(root) if root is not None else photo_root()
    if not root.is_dir():
        raise RuntimeError(f'{root}: photo folder not found (set AMPI_PHOTO_ROOT)')
    paths = image_files(root)
    if split is not None:
        paths = [p for p in paths if photo_split(p) == split]
    if not paths:
        raise RuntimeError(f'{root}: no {split or ""} photos found'.replace('  ', ' '))
    return paths


def load_photo(path, max_side):
    """RGB uint8 array, downscaled so that its longer side is at most max_side."""
    try:
        with Image.open(path) as image:
            image.draft('RGB', (max_side, max_side))   # JPEG: decode at a reduced DCT scale
            image = image.convert('RGB')
            scale = max_side / max(image.size)
            if scale < 1:
                size = (max(1, round(image.width * scale)), max(1, round(image.height * scale)))
                image = image.resize(size, Image.BILINEAR, reducing_gap=2.0)
            return np.asarray(image, dtype=np.uint8)
    except OSError as error:
        raise RuntimeError(f'{path}: cannot decode photo ({error})') from error

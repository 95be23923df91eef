#!/usr/bin/env python3
"""More training photos, from Debian's package archive (the one archive this machine
reaches).

    /usr/bin/python3 training/archive_photos.py      # -> training/data_cache/photos

Makes training/data_cache/photos, a photo root for training (AMPI_PHOTO_ROOT, --images):
a link to each folder of ../shared/data/photos, and the folder archive/ with the 40
photographs listed below, taken from four Debian packages (`apt-get download`, `dpkg -x`;
no root needed), long side brought to at most MAX_SIDE. Nothing goes into git.

Every archive photo is a training photo (photo_folder.TRAINING_ONLY_FOLDERS): the
validation and test photos stay those of ../shared, so every WHDR measured before
still compares. Idempotent: photos already there are kept, packages already downloaded
are not fetched again.

Which images: every photograph of a three-dimensional scene in these packages, chosen
by looking at them before any network saw them. Left out: patterns, illustrations and
abstract renders (lomiri's analogpattern, greentock, umang, Fossa, Infinite-Sea,
Painting-Colors), charts, text, chessboards and calibration series, the second view of
every stereo pair or sequence, and smarties.png (a rendering on white).
"""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
import photo_folder  # noqa: E402

HERE = Path(__file__).resolve().parent
CACHE = HERE / 'data_cache'
ROOT = CACHE / 'photos'
MAX_SIDE = 2048   # as ../shared's debian folder

# package: (folder inside it, prefix of the names here, photos, licence)
PACKAGES = {
    'lomiri-wallpapers-16.04': ('usr/share/backgrounds', 'lomiri', [
        'Bridge_by_Sander_Klootwijk.jpg', 'Dragonfly_by_Bolly.jpg', 'Picture_0B_by_freespace.jpg',
        'Picture_1A_by_freespace.jpg', 'Wine_by_Jakkub_Mede.jpg', 'aitzgorri_by_Aitzol_Berasategi.jpg',
        'free_by_Peter_Nerlich.jpg', 'friends_by_Aitzol_Berasategi.jpg', 'life_by_Aitzol_Berasategi.jpg',
        'picosdeeuropa_by_Aitzol_Berasategi.jpg', 'seeding_by_Clements_Engelhardt.jpg',
        'sunset_by_Aitzol_Berasategi.jpg'], 'CC-BY-4.0, CC-BY-SA-4.0 or CC0-1.0 (its copyright file)'),
    'lomiri-wallpapers-20.04': ('usr/share/backgrounds', 'lomiri', [
        'Kleiber_by_Lukas_Baubkus.jpg'], 'CC-BY-SA-3.0'),
    'opencv-doc': ('usr/share/doc/opencv-doc/examples/data', 'opencv', [
        'aero1.jpg', 'aloeL.jpg', 'apple.jpg', 'baboon.jpg', 'basketball1.png', 'board.jpg',
        'box_in_scene.png', 'building.jpg', 'butterfly.jpg', 'chicky_512.png', 'ela_original.jpg',
        'fruits.jpg', 'graf1.png', 'home.jpg', 'left.jpg', 'leuvenA.jpg', 'messi5.jpg', 'orange.jpg',
        'rubberwhale1.png', 'squirrel_cls.jpg', 'stuff.jpg'], "OpenCV's sample data (its copyright file)"),
    'python3-skimage': ('usr/lib/python3/dist-packages/skimage/data', 'skimage', [
        'astronaut.png', 'camera.png', 'chelsea.png', 'coffee.png', 'motorcycle_left.png', 'rocket.jpg'],
        'public domain or CC0 (skimage.data docstrings); motorcycle: Middlebury 2014 stereo'),
}


def archive_names():
    """{name under archive/: (package, path inside the package)}."""
    return {f'{prefix}_{name}': (package, f'{folder}/{name}')
            for package, (folder, prefix, names, _licence) in PACKAGES.items() for name in names}


def link_shared_folders(shared: Path):
    ROOT.mkdir(parents=True, exist_ok=True)
    for folder in sorted(p for p in shared.iterdir() if p.is_dir()):
        if folder.name == photo_folder.ARCHIVE_FOLDER:
            raise SystemExit(f'{shared}: has a folder named {folder.name}, the name kept for archive photos')
        link = ROOT / folder.name
        if not link.is_symlink():
            link.symlink_to(folder.resolve(), target_is_directory=True)


def unpack(package: str, debs: Path, into: Path) -> Path:
    """The package's files under into/package (downloaded into debs/ first if missing)."""
    debs.mkdir(parents=True, exist_ok=True)
    if not list(debs.glob(f'{package}_*.deb')):
        subprocess.run(['apt-get', 'download', package], cwd=debs, check=True)
    deb = sorted(debs.glob(f'{package}_*.deb'))[-1]
    subprocess.run(['dpkg', '-x', str(deb), str(into / package)], check=True)
    return into / package


def save_downscaled(source: Path, target: Path):
    """source with its long side at most MAX_SIDE, written whole or not at all."""
    with Image.open(source) as image:
        image = image.convert('RGB')
        image.thumbnail((MAX_SIDE, MAX_SIDE), Image.LANCZOS)
        partial = target.with_name(target.name + '.part')
        image.save(partial, format='JPEG' if target.suffix == '.jpg' else 'PNG', quality=95)
    os.replace(partial, target)


def fetch_archive_photos():
    out = ROOT / photo_folder.ARCHIVE_FOLDER
    out.mkdir(parents=True, exist_ok=True)
    missing = {name: where for name, where in archive_names().items() if not (out / name).exists()}
    with tempfile.TemporaryDirectory() as tmp:
        unpacked = {}
        for name, (package, inside) in sorted(missing.items()):
            if package not in unpacked:
                unpacked[package] = unpack(package, CACHE / 'debs', Path(tmp))
            source = unpacked[package] / inside
            if not source.is_file():
                raise SystemExit(f'{package}: has no {inside} (a newer version of the package?)')
            save_downscaled(source, out / name)
    return len(missing)


def main():
    link_shared_folders(photo_folder.DEFAULT_PHOTO_ROOT)
    fetched = fetch_archive_photos()
    count = len(photo_folder.list_photos(root=ROOT))
    print(f'{ROOT}: {count} photos ({fetched} archive photos fetched now, {len(archive_names())} in all)')


if __name__ == '__main__':
    main()

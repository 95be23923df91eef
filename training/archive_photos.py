#!/usr/bin/env python3
"""More training photos, from Debian's package archive (the one archive this machine
reaches).

    /usr/bin/python3 training/archive_photos.py      # -> training/data_cache/photos

Makes training/data_cache/photos, a photo root for training (AMPI_PHOTO_ROOT, --images):
a link to each folder of ../shared/data/photos, and the folder archive/ with the 251
photographs listed below, taken from nineteen Debian packages (`apt-get download`, `dpkg -x`;
no root needed; gcompris-qt-data's photos read out of its Qt resource files), long side
brought to at most MAX_SIDE. Nothing goes into git.

No archive photo is a validation photo (photo_folder.NO_VALIDATION_FOLDERS): the
validation and test photos stay those of ../shared, so every WHDR measured before
still compares. They train, but for half of the photos of each of the two later groups
of packages, the ordinal set's holdout (photo_folder.HOLDOUT_GROUPS). Idempotent: photos
already there are kept,
packages already downloaded are not fetched again.

Which images: every photograph of a three-dimensional scene in these packages, chosen
by looking at them before any network saw them. Left out: patterns, illustrations and
abstract renders (lomiri's analogpattern, greentock, umang, Fossa, Infinite-Sea,
Painting-Colors), charts, text, chessboards and calibration series, the second view of
every stereo pair or sequence, and smarties.png (a rendering on white); later (the last
three packages, and plasma-workspace-wallpapers' largest landscape file of each wallpaper)
every illustration and render of plasma-workspace-wallpapers, mate-backgrounds' desktop and
abstract folders (graphics, and Elephants, a painting), and gcompris-qt-data's images below
800 px on the long side (categorization, details and the like: 320-700 px), which were not
looked at. Packages looked at and left out whole: gnome-backgrounds (renders), ukui-wallpapers
(illustrations), sway-backgrounds (logos). The last group (palapeli-data to gimp-help-en,
67 photos) came from a search of about forty packages (documentation, games, login and
desktop themes), every image of 600 px or more looked at on contact sheets by a helper
agent: left out were screenshots, cut-outs, flat textures and illustrations (desktop-base,
xfdesktop4-data, the other sddm themes, fotoxx, kdenlive and the rest had nothing else),
and, within the packages kept, photos with little depth to order (a sunset, the moon behind
branches, a flower or a pizza filling the frame, a Mars sky) and the four KPhotoAlbum demo
photos whose rotation lives outside the file. A later search of 76 more packages the same way
(image libraries' documentation and test data, toolkit examples, window-manager, boot and
desktop themes, games, science packages) found 18 photos in 10 of them, several
greyscale, captioned or of no stated origin: too few for a third group, so none is here.
"""

import io
import os
import struct
import subprocess
import sys
import tempfile
import zlib
from pathlib import Path

from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
import photo_folder  # noqa: E402

HERE = Path(__file__).resolve().parent
CACHE = HERE / 'data_cache'
ROOT = CACHE / 'photos'
MAX_SIDE = 2048   # as ../shared's debian folder

GCOMPRIS_LICENCE = 'per photo in its copyright file (CC-BY-SA, CC0, GPL)'

# (package, folder inside it, prefix of the names here, photos, licence). A folder ending
# in .rcc/... is a folder inside that Qt resource file of the package (read_rcc). A photo
# is its path under the folder, or (that path, its name here); by default its name here is
# the path with '/' as '_', WebP photos saved as JPEG.
SOURCES = [
    ('lomiri-wallpapers-16.04', 'usr/share/backgrounds', 'lomiri', [
        'Bridge_by_Sander_Klootwijk.jpg', 'Dragonfly_by_Bolly.jpg', 'Picture_0B_by_freespace.jpg',
        'Picture_1A_by_freespace.jpg', 'Wine_by_Jakkub_Mede.jpg', 'aitzgorri_by_Aitzol_Berasategi.jpg',
        'free_by_Peter_Nerlich.jpg', 'friends_by_Aitzol_Berasategi.jpg', 'life_by_Aitzol_Berasategi.jpg',
        'picosdeeuropa_by_Aitzol_Berasategi.jpg', 'seeding_by_Clements_Engelhardt.jpg',
        'sunset_by_Aitzol_Berasategi.jpg'], 'CC-BY-4.0, CC-BY-SA-4.0 or CC0-1.0 (its copyright file)'),
    ('lomiri-wallpapers-20.04', 'usr/share/backgrounds', 'lomiri', [
        'Kleiber_by_Lukas_Baubkus.jpg'], 'CC-BY-SA-3.0'),
    ('opencv-doc', 'usr/share/doc/opencv-doc/examples/data', 'opencv', [
        'aero1.jpg', 'aloeL.jpg', 'apple.jpg', 'baboon.jpg', 'basketball1.png', 'board.jpg',
        'box_in_scene.png', 'building.jpg', 'butterfly.jpg', 'chicky_512.png', 'ela_original.jpg',
        'fruits.jpg', 'graf1.png', 'home.jpg', 'left.jpg', 'leuvenA.jpg', 'messi5.jpg', 'orange.jpg',
        'rubberwhale1.png', 'squirrel_cls.jpg', 'stuff.jpg'], "OpenCV's sample data (its copyright file)"),
    ('python3-skimage', 'usr/lib/python3/dist-packages/skimage/data', 'skimage', [
        'astronaut.png', 'camera.png', 'chelsea.png', 'coffee.png', 'motorcycle_left.png', 'rocket.jpg'],
        'public domain or CC0 (skimage.data docstrings); motorcycle: Middlebury 2014 stereo'),
    # the sources below came a session later (training/ordinal/README.md)
    ('plasma-workspace-wallpapers', 'usr/share/wallpapers', 'plasma', [
        (f'{name}/contents/images/2560x1600.jpg', f'{name}.jpg') for name in (
            'BytheWater', 'ColdRipple', 'ColorfulCups', 'DarkestHour', 'EveningGlow', 'FallenLeaf', 'Grey',
            'Kite', 'OneStandsOut', 'Path', 'summer_1am')], 'GPL-2+'),
    ('mate-backgrounds', 'usr/share/backgrounds/mate/nature', 'mate', [
        'Aqua.jpg', 'Blinds.jpg', 'Dune.jpg', 'FreshFlower.jpg', 'Garden.jpg', 'GreenMeadow.jpg',
        'LadyBird.jpg', 'RainDrops.jpg', 'Storm.jpg', 'TwoWings.jpg', 'Wood.jpg', 'YellowFlower.jpg'],
        'GPL-2+ (its copyright file)'),
    ('gcompris-qt-data', 'usr/share/gcompris-qt/rcc/erase.rcc/gcompris/src/activities/erase/resource',
     'gcompris_erase', [f'{name}.webp' for name in (
         'alpaca', 'bee', 'butterfly', 'calf', 'camels', 'caterpillar', 'chamaeleon', 'cheetah', 'crab',
         'dolphin', 'flying_fox', 'gibbon', 'giraffe', 'goat', 'gorilla', 'gosling', 'heron', 'horse',
         'kingfisher', 'kitten', 'long_nosed_monkey', 'macaque', 'meerkats', 'northern_harrier',
         'nubian_ibex', 'penguin', 'pika', 'red_panda', 'rhinoceros', 'spoonbills', 'squirrel', 'swans',
         'toucan')], GCOMPRIS_LICENCE),
    ('gcompris-qt-data', 'usr/share/gcompris-qt/rcc/explore_monuments.rcc/gcompris/src/activities/'
     'explore_monuments/resource', 'gcompris_monuments', [f'{name}.webp' for name in (
         'egypt/bentPyramid', 'egypt/greatPyramidOfGiza', 'egypt/meidumPyramid', 'egypt/redPyramid',
         'france/arlesAmphitheater', 'france/chateaudeChambord', 'france/chateaudeChenonceau',
         'france/citedeCarcassonne', 'france/eiffelTower', 'france/montStMichel', 'france/palaisdesPapes',
         'france/pontduGard', 'france/reimsCathedral', 'france/rocamadour', 'germany/aulaPalatina',
         'germany/berlinCathedral', 'germany/brandenburgGate', 'germany/neuschwansteinCastle',
         'germany/schwerinPalace', 'germany/trierImperialBaths', 'germany/wormsCathedral', 'india/ajantaCave',
         'india/charminar', 'india/gatewayofIndia', 'india/goldenTemple', 'india/greatStupa',
         'india/hawaMahal', 'india/konarkSunTemple', 'india/mysorePalace', 'india/qutubMinar',
         'india/rangGhar', 'india/victoriaMemorial', 'usa/cabrillo', 'usa/canyondeChelly',
         'usa/castillodeSanMarcos', 'usa/castleClinton', 'usa/fortSumter', 'usa/georgeWashingtonBirthplace',
         'usa/lincolnMemorial', 'usa/mountRushmore', 'usa/navajo', 'usa/statueofLiberty',
         'wonders/chichenItza', 'wonders/christTheRedeemer', 'wonders/colosseum', 'wonders/greatWallofChina',
         'wonders/machuPicchu', 'wonders/petra', 'wonders/tajMahal')],
     GCOMPRIS_LICENCE),
    ('gcompris-qt-data', 'usr/share/gcompris-qt/rcc/explore_farm_animals.rcc/gcompris/src/activities/'
     'explore_farm_animals/resource/animals', 'gcompris_farm', [f'{name}.webp' for name in (
         'cat', 'chicken', 'cow', 'dog', 'duck', 'horse', 'owl', 'pig', 'sheep')],
     GCOMPRIS_LICENCE),
    ('gcompris-qt-data', 'usr/share/gcompris-qt/rcc/explore_world_animals.rcc/gcompris/src/activities/'
     'explore_world_animals/resource/animals', 'gcompris_animals', [f'{name}.webp' for name in (
         'bison', 'chameleon', 'crocodile', 'dragon', 'giraffe', 'hedgehog', 'jaguar', 'kangaroo', 'koala',
         'lemur', 'moose', 'narwhal', 'panda', 'polar_bear', 'scarlet_macaw')],
     GCOMPRIS_LICENCE),
    ('gcompris-qt-data', 'usr/share/gcompris-qt/rcc/explore_world_music.rcc/gcompris/src/activities/'
     'explore_world_music/resource/music', 'gcompris_music', [f'{name}.webp' for name in (
         'africa', 'america', 'australia', 'ireland', 'italy', 'japan', 'mexico', 'middleeast', 'orchestra')],
     GCOMPRIS_LICENCE),
    ('gcompris-qt-data', 'usr/share/gcompris-qt/rcc/clickgame.rcc/gcompris/src/activities/clickgame/resource',
     'gcompris_sea', [f'sea{k}.webp' for k in range(1, 7)], GCOMPRIS_LICENCE),
    # and these later still (photo_folder.HOLDOUT_GROUPS' second group): photos found in
    # documentation, games and themes, looked at as contact sheets
    ('palapeli-data', 'usr/share/palapeli/collection', 'palapeli', [
        'castle-maintenon.jpg', 'cincinnati-bridge.jpg', 'european-honey-bee.jpg',
        'panther-chameleon-female.jpg'], 'GPL-2+ (the package\'s Files: *)'),
    ('python3-sklearn', 'usr/lib/python3/dist-packages/sklearn/datasets/images', 'sklearn', [
        'china.jpg'], 'BSD-3-Clause'),
    ('scribus-template', 'usr/share/scribus/templates', 'scribus', [
        'br2/nature.jpg', 'br2/sunset.jpg'], 'public domain (Riku Leino\'s templates)'),
    ('sddm-theme-maldives', 'usr/share/sddm/themes/maldives', 'sddm_maldives', [
        'background.jpg'], 'CC-BY-3.0'),
    ('tuxpaint-data', 'usr/share/tuxpaint/templates', 'tuxpaint', [f'{name}.jpg' for name in (
        'cliff', 'corn_maze', 'jellyfish', 'lighthouse', 'mossy_log', 'mudstone', 'ocean_waves',
        'redwoods_above', 'rocks', 'sheep', 'spiders_web', 'sun_behind_leaves', 'trees_above',
        'wool_mill_machine')], 'GPL-2+ (the package\'s Files: *)'),
    ('lxqt-themes', 'usr/share/lxqt/wallpapers', 'lxqt', [
        'Butterfly-Kenneth-Wimer.jpg', 'Valendas.png', 'appleflower.png', 'beam.png', 'butterfly.png',
        'drop.png', 'flowers.png', 'fog.jpg', 'this-is-not-windows.jpg'], 'CC-BY-SA-3.0 (its License file)'),
    ('tuxtype-data', 'usr/share/tuxtype/images', 'tuxtype', [
        *(f'kcas{k}.jpg' for k in range(12)), 'hidden.jpg'], 'GPL (the package\'s copyright file)'),
    ('digikam-data', 'usr/share/digikam/about/images', 'digikam', ['body-background.jpg'], 'GPL-2'),
    ('hugin-data', 'usr/share/hugin/xrc/data/help_en_EN', 'hugin', [
        'CA_fringes00.jpg', 'CA_tCA00.jpg'], 'GPL-2+'),
    # KPhotoAlbum's demo keeps four photos' rotation in its index.xml, not in the JPEG:
    # grand_canyon_1, new_wave_1, pool_2 and wayne are left out rather than guessed upright
    ('kphotoalbum', 'usr/share/kphotoalbum/demo', 'kphotoalbum', [f'{name}.jpg' for name in (
        'anne_helene', 'bar55', 'bar55_2', 'blackie', 'cold_water', 'donna', 'donna_2', 'grand_canyon_2',
        'grand_canyon_3', 'jesper_2', 'new_wave_2', 'pool', 'skagen', 'skagen_2', 'snow', 'spiff',
        'spiff_2')], 'GPL-2'),
    ('puzzle-jigsaw', 'usr/share/puzzle-jigsaw/samples', 'jigsaw', [
        ('pexels-photo-302304.jpeg', 'tiger.jpg')], 'CC0-1.0'),
    ('gimp-help-en', 'usr/share/gimp/2.0/help/en/images/tutorials/tone-mapping', 'gimphelp', [
        ('truck-tone-mapped-using-gegl-mantuik.jpg', 'truck.jpg'), 'power-lines.jpg'],
     'GFDL (the GIMP manual)'),
]


def name_here(photo) -> tuple:
    """(path under the source's folder, name under archive/) of one SOURCES photo."""
    if isinstance(photo, tuple):
        return photo
    name = photo.replace('/', '_')
    return photo, name[:-len('.webp')] + '.jpg' if name.endswith('.webp') else name


def archive_names():
    """{name under archive/: (package, path inside the package)}."""
    return {f'{prefix}_{here}': (package, f'{folder}/{inside}')
            for package, folder, prefix, photos, _licence in SOURCES
            for inside, here in map(name_here, photos)}


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


def read_rcc(path: Path) -> dict:
    """{path inside: bytes} of every file in a Qt resource file (rcc format 1-3: a header,
    a tree of 14- or 22-byte nodes, a data block, a block of UTF-16 names; a file's data
    may be zlib-compressed, a zstd-compressed one is left out)."""
    blob = path.read_bytes()
    if blob[:4] != b'qres':
        raise SystemExit(f'{path}: not a Qt resource file')
    version, tree, data, names = struct.unpack('>4I', blob[4:20])
    node_size = 22 if version >= 2 else 14

    def name(offset):
        length = struct.unpack_from('>H', blob, names + offset)[0]
        return blob[names + offset + 6:names + offset + 6 + 2 * length].decode('utf-16-be')

    files = {}

    def walk(node, prefix):
        at = tree + node * node_size
        name_offset, flags = struct.unpack_from('>IH', blob, at)
        here = f'{prefix}/{name(name_offset)}' if node else ''
        if flags & 2:   # a directory: its children are nodes first .. first + count - 1
            count, first = struct.unpack_from('>2I', blob, at + 6)
            for child in range(first, first + count):
                walk(child, here)
            return
        offset = data + struct.unpack_from('>I', blob, at + 10)[0]
        content = blob[offset + 4:offset + 4 + struct.unpack_from('>I', blob, offset)[0]]
        if flags & 1:   # zlib, after the 4-byte uncompressed size
            content = zlib.decompress(content[4:])
        if not flags & 4:
            files[here.lstrip('/')] = content

    walk(0, '')
    return files


def read_source(package_files: Path, inside: str, resources: dict) -> bytes:
    """The bytes of a SOURCES photo: a file of the unpacked package, or a file inside one
    of its .rcc files (each read once, kept in resources)."""
    if '.rcc/' in inside:
        rcc, inner = inside.split('.rcc/', 1)
        if rcc not in resources:
            resources[rcc] = read_rcc(package_files / f'{rcc}.rcc')
        if inner not in resources[rcc]:
            raise SystemExit(f'{package_files.name}: {rcc}.rcc has no {inner} (a newer version of the package?)')
        return resources[rcc][inner]
    if not (package_files / inside).is_file():
        raise SystemExit(f'{package_files.name}: has no {inside} (a newer version of the package?)')
    return (package_files / inside).read_bytes()


def save_downscaled(source: bytes, target: Path):
    """The photo in source with its long side at most MAX_SIDE, written whole or not at all."""
    with Image.open(io.BytesIO(source)) as image:
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
        unpacked, resources = {}, {}
        for name, (package, inside) in sorted(missing.items()):
            if package not in unpacked:
                unpacked[package] = unpack(package, CACHE / 'debs', Path(tmp))
                resources[package] = {}
            save_downscaled(read_source(unpacked[package], inside, resources[package]), out / name)
    return len(missing)


def main():
    link_shared_folders(photo_folder.DEFAULT_PHOTO_ROOT)
    fetched = fetch_archive_photos()
    count = len(photo_folder.list_photos(root=ROOT))
    print(f'{ROOT}: {count} photos ({fetched} archive photos fetched now, {len(archive_names())} in all)')


if __name__ == '__main__':
    main()

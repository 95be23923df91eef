#!/usr/bin/env python3
"""The real-photo ordinal set: point pairs drawn on the photos, marked images to label
them by eye, and the merged label file.

    export AMPI_PHOTO_ROOT=training/data_cache/photos  # ../shared's photos and the archive's
    /usr/bin/python3 training/ordinal/pairs.py sample            # -> training/ordinal/pairs.json.gz
    /usr/bin/python3 training/ordinal/pairs.py draw --out /tmp/ordinal_marked [--round N] [--only REL...]
    /usr/bin/python3 training/ordinal/pairs.py merge             # labels/*.tsv -> ordinal.json.gz
    /usr/bin/python3 training/ordinal/pairs.py subset OUT [--prefix archive/...] [--rounds 1-2] [--kind edge]

(training/archive_photos.py makes that root; `sample` from ../shared alone would leave the
archive photos out.)

Pairs come from a fixed seed and each photo's own name, so `sample` always makes the same
file. Per photo and round: RANDOM_PAIRS pairs of points uniform over the photo, and
EDGE_PAIRS pairs straddling a strong image edge (the two points on either side of it,
along the gradient), so the set also asks about object boundaries. Rounds were labelled
one after another (round 1: pairs 1-7, round 2: 8-14, ..., round 7: 43-49); a new
round adds pairs and leaves the earlier ones, and their labels, as they were. The
validation photos' pairs of TEST_ROUNDS are merged as a part of their own, split 'test'.
A photo's split is photo_folder.ordinal_split's: 'train', 'val', or 'holdout' (half of the
archive photos labelled last).
Nothing here looks at any network's output: the labels are what a person (or labelling
agent) sees in the marked image (INSTRUCTIONS.md). Coordinates are pixels of the photo
upright (turned by its EXIF orientation, as `ampi` reads it; x right, y down).
"""

import argparse
import gzip
import hashlib
import json
import math
import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFilter, ImageFont, ImageOps

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import photo_folder  # noqa: E402  (the photo listing and the split)

HERE = Path(__file__).resolve().parent
PAIRS_FILE = HERE / 'pairs.json.gz'   # gzip: it travels to GPU machines with the working tree
LABELS_DIR = HERE / 'labels'
ORDINAL_FILE = HERE / 'ordinal.json.gz'  # gzip too; the label files are what a review reads

SEED = 2026
RANDOM_PAIRS = 5
EDGE_PAIRS = 2
BORDER = 0.04            # points keep this share of each side away from the border
MIN_RANDOM_GAP = 0.08    # random pair points at least this share of the diagonal apart
EDGE_OFFSET = 0.02       # edge pair points this share of the long side from the edge
EDGE_QUANTILE = 0.98     # edge pixels: gradient magnitude above this quantile
DISPLAY_LONG_SIDE = 1024
ZOOM = 4.5                # edge pairs again below the photo, this many times the shown size
ROUNDS = 23
# The validation photos' pairs of these rounds are the test part (split 'test'): no
# network is ever selected on them. Rounds 1 and 2 of the validation photos had picked
# the bundled networks, and on the fresh round 3 lite scored far worse than on them.
# Rounds 5, 6 and 8 joined them to shrink the part's sampling error; rounds 7 and 9
# joined `val`. Rounds 10-13 joined `test` before the long heavy run had a candidate: on
# 1,005 ordered pairs, its bar "no worse on `test`" (training/DEPTH.md) was nearly a coin toss.
# Rounds 14-19 joined it too before they were labelled, the long run still without one, and
# rounds 20-23 when they were drawn, before any of them was labelled.
TEST_ROUNDS = (3, 5, 6, 8, *range(10, ROUNDS + 1))
PAIRS_PER_ROUND = RANDOM_PAIRS + EDGE_PAIRS
LABELS = ('A', 'B', '=')   # A nearer, B nearer, too close to call
PALETTE = [(255, 40, 40), (40, 220, 40), (60, 120, 255), (255, 220, 0), (255, 0, 255),
           (0, 230, 230), (255, 140, 0)]


def load_upright(path):
    """The photo as ampi reads it: RGB, turned by its EXIF orientation."""
    with Image.open(path) as image:
        return ImageOps.exif_transpose(image).convert('RGB')


def photo_rng(rel, round_no):
    """Round 1 keeps the stream it was labelled with; later rounds get their own."""
    key = f'{SEED}:{rel}' if round_no == 1 else f'{SEED}:{rel}:round{round_no}'
    digest = hashlib.sha256(key.encode()).digest()
    return np.random.default_rng(int.from_bytes(digest[:8], 'little'))


def random_pairs(rng, w, h, count):
    lo = np.array([BORDER * w, BORDER * h])
    hi = np.array([(1 - BORDER) * w, (1 - BORDER) * h])
    pairs = []
    while len(pairs) < count:
        a, b = rng.uniform(lo, hi), rng.uniform(lo, hi)
        if np.hypot(*(a - b)) >= MIN_RANDOM_GAP * math.hypot(w, h):
            pairs.append((a, b))
    return pairs


def edge_pairs(rng, gray, count):
    """Points on both sides of strong edges: gradient of the blurred grey image, an edge
    pixel drawn among the strongest, the two points EDGE_OFFSET away along the gradient."""
    h, w = gray.shape
    gy, gx = np.gradient(gray)
    magnitude = np.hypot(gx, gy)
    d = EDGE_OFFSET * max(w, h)
    margin = np.array([BORDER * w + d, BORDER * h + d])
    ys, xs = np.nonzero(magnitude >= np.quantile(magnitude, EDGE_QUANTILE))
    inside = (xs >= margin[0]) & (xs < w - margin[0]) & (ys >= margin[1]) & (ys < h - margin[1])
    xs, ys = xs[inside], ys[inside]
    pairs = []
    for i in rng.permutation(len(xs)):
        p = np.array([xs[i], ys[i]], float)
        if any(np.hypot(*(p - q)) < 4 * d for q, _ in pairs):
            continue   # spread the edge pairs over the photo
        normal = np.array([gx[ys[i], xs[i]], gy[ys[i], xs[i]]])
        normal /= np.linalg.norm(normal)
        pairs.append((p, normal))
        if len(pairs) == count:
            break
    out = []
    for p, normal in pairs:
        a, b = p - d * normal, p + d * normal
        out.append((a, b) if rng.random() < 0.5 else (b, a))
    return out


def round_of(pair_id):
    return (pair_id - 1) // PAIRS_PER_ROUND + 1


def sample_photo(path, rel):
    rgb = load_upright(path)
    w, h = rgb.size
    gray = np.asarray(rgb.convert('L').filter(ImageFilter.GaussianBlur(2)), np.float32)
    pairs = []
    for round_no in range(1, ROUNDS + 1):
        rng = photo_rng(rel, round_no)
        pairs += [('random', a, b) for a, b in random_pairs(rng, w, h, RANDOM_PAIRS)]
        pairs += [('edge', a, b) for a, b in edge_pairs(rng, gray, EDGE_PAIRS)]
    return {'photo': rel, 'width': w, 'height': h, 'split': photo_folder.ordinal_split(path),
            'pairs': [{'id': i + 1, 'kind': kind,
                       'a': [round(float(a[0]), 1), round(float(a[1]), 1)],
                       'b': [round(float(b[0]), 1), round(float(b[1]), 1)]}
                      for i, (kind, a, b) in enumerate(pairs)]}


def write_set(path: Path, header: dict, photos: list):
    """header's keys and the photos as JSON, one pair per line (a third of the size of an
    indented dump, and readable once decompressed). A path ending in .gz is compressed,
    with no time stamp, so the same set makes the same bytes."""
    lines = [f' {json.dumps(k)}: {json.dumps(v)},' for k, v in header.items()] + [' "photos": [']
    for n, entry in enumerate(photos):
        fields = json.dumps({k: v for k, v in entry.items() if k != 'pairs'})[:-1]
        pairs = ',\n'.join(f'   {json.dumps(pair)}' for pair in entry['pairs'])
        lines.append(f'  {fields}, "pairs": [\n{pairs}\n  ]}}' + (',' if n + 1 < len(photos) else ''))
    text = '{\n' + '\n'.join(lines) + '\n ]\n}\n'
    if path.suffix == '.gz':
        path.write_bytes(gzip.compress(text.encode(), mtime=0))
    else:
        path.write_text(text)


def read_pairs(path: Path = PAIRS_FILE) -> list:
    """The photos of a pair file (PAIRS_FILE), each with its pairs."""
    return photo_folder.read_json(path)['photos']


def cmd_sample(args):
    root = photo_folder.photo_root()
    photos = [sample_photo(p, p.relative_to(root).as_posix()) for p in photo_folder.list_photos()]
    write_set(PAIRS_FILE, {'seed': SEED}, photos)
    n = sum(len(p['pairs']) for p in photos)
    print(f'{PAIRS_FILE}: {n} pairs on {len(photos)} photos')


# ----------------------------------------------------------------------------------
# Marked images

def font(size):
    try:
        return ImageFont.truetype('/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf', size)
    except OSError:
        return ImageFont.load_default()


def mark(draw, xy, shape, colour, text, radius, text_size):
    x, y = xy
    box = [x - radius, y - radius, x + radius, y + radius]
    for width, c in ((4, (0, 0, 0)), (2, colour)):
        (draw.ellipse if shape == 'circle' else draw.rectangle)(box, outline=c, width=width)
    draw.text((x + radius + 2, y - radius - text_size), text, fill=colour, font=font(text_size),
              stroke_width=2, stroke_fill=(0, 0, 0))


def draw_photo(path, entry, round_no):
    """The photo at DISPLAY_LONG_SIDE with every pair of one round marked (A a circle,
    B a square, one colour per pair), and below it an enlarged crop around each edge pair."""
    photo = load_upright(path)
    scale = DISPLAY_LONG_SIDE / max(photo.size)
    shown = photo.resize((round(photo.width * scale), round(photo.height * scale)), Image.LANCZOS)
    draw = ImageDraw.Draw(shown)
    pairs = [p for p in entry['pairs'] if round_of(p['id']) == round_no]
    for pair in pairs:
        colour = PALETTE[(pair['id'] - 1) % len(PALETTE)]
        for key, shape in (('a', 'circle'), ('b', 'square')):
            xy = [c * scale for c in pair[key]]
            mark(draw, xy, shape, colour, f"{pair['id']}{key.upper()}", 7, 18)
    crops = [zoom_crop(photo, pair) for pair in pairs if pair['kind'] == 'edge']
    strip_h = max((c.height for c in crops), default=0)
    canvas = Image.new('RGB', (max(shown.width, sum(c.width + 8 for c in crops)),
                               shown.height + (strip_h + 8 if crops else 0)), (32, 32, 32))
    canvas.paste(shown, (0, 0))
    x = 0
    for crop in crops:
        canvas.paste(crop, (x, shown.height + 8))
        x += crop.width + 8
    return canvas


def zoom_crop(photo, pair, size=(480, 300)):
    """The photo around one pair at ZOOM times the shown size, the pair marked again."""
    scale = ZOOM * DISPLAY_LONG_SIDE / max(photo.size)   # crop pixels per photo pixel
    centre = [(pair['a'][i] + pair['b'][i]) / 2 for i in range(2)]
    reach = (size[0] / 2 / scale, size[1] / 2 / scale)
    box = [centre[0] - reach[0], centre[1] - reach[1], centre[0] + reach[0], centre[1] + reach[1]]
    crop = photo.crop([round(v) for v in box]).resize(size, Image.LANCZOS)
    draw = ImageDraw.Draw(crop)
    colour = PALETTE[(pair['id'] - 1) % len(PALETTE)]
    for key, shape in (('a', 'circle'), ('b', 'square')):
        xy = [(pair[key][0] - box[0]) * scale, (pair[key][1] - box[1]) * scale]
        mark(draw, xy, shape, colour, f"{pair['id']}{key.upper()}", 9, 20)
    return crop


def cmd_draw(args):
    root = photo_folder.photo_root()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    entries = read_pairs()
    if args.only:
        entries = [e for e in entries if e['photo'] in set(args.only)]
    for entry in entries:
        target = out / (entry['photo'].replace('/', '__').rsplit('.', 1)[0] + '.png')
        draw_photo(root / entry['photo'], entry, args.round).save(target)
    print(f'{out}: {len(entries)} marked images')


# ----------------------------------------------------------------------------------
# Merging the labels

def read_labels(folder):
    """{(photo, pair id): [label, ...]} from every labels/*.tsv (photo, pair id, A|B|=),
    one entry per labeller (file) that labelled the pair."""
    labels = {}
    for tsv in sorted(Path(folder).glob('*.tsv')):
        seen = {}
        for n, line in enumerate(tsv.read_text().splitlines(), 1):
            if not line.strip() or line.startswith('#'):
                continue
            fields = line.split('\t')
            if len(fields) != 3 or fields[2] not in LABELS or not fields[1].isdigit():
                raise SystemExit(f'{tsv}:{n}: expected "photo<TAB>pair<TAB>A|B|=", got {line!r}')
            key = (fields[0], int(fields[1]))
            if key in seen and seen[key] != fields[2]:
                raise SystemExit(f'{tsv}:{n}: {key} labelled twice in one file, differently')
            seen[key] = fields[2]
        for key, label in seen.items():
            labels.setdefault(key, []).append(label)
    return labels


def consensus(votes):
    """A pair keeps an order only when every labeller who saw it gave that order;
    anything else (a '=' beside an order, or A against B) is too close to call."""
    return votes[0] if len(set(votes)) == 1 else '='


def agreement(labels):
    """Counts over pairs labelled more than once: (pairs, same label, A against B)."""
    multi = [v for v in labels.values() if len(v) > 1]
    same = sum(len(set(v)) == 1 for v in multi)
    opposite = sum({'A', 'B'} <= set(v) for v in multi)
    return len(multi), same, opposite


def split_parts(split, pairs):
    """(split, pairs) entries of one photo: a validation photo's pairs of TEST_ROUNDS go
    to an entry of their own, split 'test'; empty parts are left out."""
    if split != 'val':
        return [(split, pairs)] if pairs else []
    test = [p for p in pairs if round_of(p['id']) in TEST_ROUNDS]
    val = [p for p in pairs if round_of(p['id']) not in TEST_ROUNDS]
    return [(s, part) for s, part in (('val', val), ('test', test)) if part]


def cmd_merge(args):
    labels = read_labels(LABELS_DIR)
    photos = read_pairs()
    known = {(e['photo'], p['id']) for e in photos for p in e['pairs']}
    unknown = sorted(set(labels) - known)
    if unknown:
        raise SystemExit(f'{LABELS_DIR}: labels for pairs that {PAIRS_FILE.name} does not have: {unknown[:3]}')
    merged = []
    for entry in photos:
        pairs = [dict(p, label=consensus(labels[(entry['photo'], p['id'])]),
                      votes=''.join(labels[(entry['photo'], p['id'])]))
                 for p in entry['pairs'] if (entry['photo'], p['id']) in labels]
        for split, part in split_parts(entry['split'], pairs):
            merged.append({k: entry[k] for k in ('photo', 'width', 'height')} | {'split': split, 'pairs': part})
    write_set(ORDINAL_FILE, {
        'seed': SEED, 'labels': 'A: a nearer, B: b nearer, =: too close to call',
        'votes': "every labeller's label; an order is kept only when all of them gave it"}, merged)
    for split in ('train', 'val', 'test', 'holdout'):
        chosen = [p for e in merged if e['split'] == split for p in e['pairs']]
        ordered = sum(p['label'] != '=' for p in chosen)
        n_photos = sum(e['split'] == split for e in merged)
        print(f'{split}: {n_photos} photos, {len(chosen)} labelled pairs, {ordered} ordered')
    multi, same, opposite = agreement(labels)
    print(f'{ORDINAL_FILE}: {len(labels)} of {len(known)} pairs labelled; {multi} labelled more than once: '
          f'{same} alike, {opposite} with A against B')


# ----------------------------------------------------------------------------------
# A part of the merged set, for a WHDR of its own

def subset(photos: list, prefixes, rounds, kind=None) -> list:
    """The entries of photos whose name starts with one of prefixes (all when none), each
    keeping only its pairs of rounds (first, last) and, when given, of one kind ('random' or
    'edge'); entries left empty are dropped."""
    first, last = rounds
    kept = [dict(e, pairs=[p for p in e['pairs'] if first <= round_of(p['id']) <= last
                           and kind in (None, p['kind'])])
            for e in photos if not prefixes or e['photo'].startswith(tuple(prefixes))]
    return [e for e in kept if e['pairs']]


def cmd_subset(args):
    whole = photo_folder.read_json(ORDINAL_FILE)
    first, _, last = args.rounds.partition('-')
    photos = subset(whole['photos'], args.prefix, (int(first), int(last or first)), args.kind)
    write_set(Path(args.out), {k: v for k, v in whole.items() if k != 'photos'}, photos)
    ordered = sum(p['label'] != '=' for e in photos for p in e['pairs'])
    print(f'{args.out}: {len(photos)} photos, {ordered} ordered pairs')


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest='command', required=True)
    sub.add_parser('sample', help='draw the pairs of every photo into pairs.json.gz')
    d = sub.add_parser('draw', help='write the marked images to label')
    d.add_argument('--out', required=True)
    d.add_argument('--round', type=int, default=ROUNDS, choices=range(1, ROUNDS + 1),
                   help='which round of pairs to mark (default the newest)')
    d.add_argument('--only', nargs='*', help='photos (relative names) to draw, default all')
    sub.add_parser('merge', help='labels/*.tsv -> ordinal.json.gz')
    s = sub.add_parser('subset', help="a part of ordinal.json.gz (some photos, some rounds) for `ampi eval depth --ordinal`")
    s.add_argument('out')
    s.add_argument('--prefix', action='append', default=[],
                   help='keep the photos whose name starts with this (repeatable; default all)')
    s.add_argument('--rounds', default=f'1-{ROUNDS}', help='keep these rounds: N or FIRST-LAST')
    s.add_argument('--kind', choices=('random', 'edge'),
                   help='keep only the uniform pairs or only those across image edges (default both)')
    args = ap.parse_args()
    {'sample': cmd_sample, 'draw': cmd_draw, 'merge': cmd_merge, 'subset': cmd_subset}[args.command](args)


if __name__ == '__main__':
    main()

#!/usr/bin/env python3
"""Rewrites the committed evaluation tables from `ampi eval`:

    /usr/bin/python3 eval/make_tables.py depth   --ampi build/ampi   # bench/RESULTS-depth-eval.md
    /usr/bin/python3 eval/make_tables.py slicing --ampi build/ampi   # bench/RESULTS-slicing.md
    AMPI_PHOTO_ROOT=training/data_cache/photos /usr/bin/python3 eval/make_tables.py ordinal --ampi build/ampi  # bench/RESULTS-ordinal.md
    /usr/bin/python3 eval/make_tables.py edges   --ampi build/ampi   # bench/RESULTS-edges.md

depth: 50 synthetic validation scenes (training/make_eval_scenes.py: exact disparity,
textured with validation photos only), `ampi eval depth` with the lite and the heavy
network. slicing: the validation photos (every tenth photo by sorted name of each folder
of ../shared/data/photos, training/photo_folder.py photo_split), `ampi eval slicing` with the
default (optimal) slicer, with the paper's rule exactly and with its former plane guard;
the tear penalty's tuning runs on training photos; the default on 50 synthetic scenes
with their exact depth. ordinal: WHDR of the lite and heavy networks on the real-photo
ordinal set (training/ordinal/), its validation photos and, for reference, its training ones,
as they are and as `ampi run` slices them (edges snapped); on val and test also the uniform
pairs and those across image edges apart, and other working sizes.
edges: `ampi eval edges` on its scene set with the built-in textures and with textures cut
from three validation photos.
The tables quote ampi's output verbatim, with the command that made it.
"""

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / 'training'))


def run(command):
    """stdout of an ampi command; stops with its stderr's last line on failure."""
    started = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()[-1:] or ['(no message)']
        sys.exit(f'make_tables.py: {" ".join(map(str, command))} failed: {tail[0]}')
    return done.stdout, time.monotonic() - started


def shown(command):
    """The command as a reader would type it from the repository root."""
    return ' '.join(str(Path(c).relative_to(REPO)) if str(c).startswith(str(REPO)) else str(c) for c in command)


def write_scenes(folder, count):
    subprocess.run([sys.executable, str(REPO / 'training' / 'make_eval_scenes.py'), folder, '--count', str(count)],
                   check=True, capture_output=True)


def first_row(out, method):
    """The numbers of METHOD's row in an ampi eval depth table."""
    for line in out.splitlines():
        fields = line.split()
        if fields and fields[0] == method:
            return [float(x) for x in fields[1:6]]
    sys.exit(f'make_tables.py: no {method} row in: {out}')


def depth_table(ampi, count, threads):
    with tempfile.TemporaryDirectory(prefix='ampi-eval-depth-') as tmp:
        write_scenes(tmp, count)
        sections = []
        for model in ('lite', 'heavy'):
            command = [ampi, 'eval', 'depth', '--images', f'{tmp}/images', '--reference', f'{tmp}/reference',
                       '--model', model, '--threads', str(threads)]
            out, seconds = run(command)
            sections.append((model, shown(command).replace(tmp, 'SCENES'), out, seconds))
    lines = [
        '# Depth metrics on synthetic validation scenes (`ampi eval depth`)',
        '',
        f'Made by `/usr/bin/python3 eval/make_tables.py depth --ampi AMPI` (it writes {count} scenes with',
        f'`training/make_eval_scenes.py SCENES --count {count}`: validation seeds 10^9 ..., 384x288, exact',
        'disparity, textured only with validation photos, never trained on), then runs the commands below.',
        'Metrics as in the paper (Luvizon et al., Table 2, after Eigen et al.), in disparity after',
        'aligning each prediction to its reference by median and standard deviation; sky pixels',
        '(disparity 0) have no measurement and are left out; RMSE is in 1/metres; means over',
        'the scenes (`ampi eval depth --help` has the exact definitions). `vertical-gradient` is',
        'a map that only grows towards the bottom of the image: the floor a network must beat.',
        '',
        '| method | delta < 1.25 | delta < 1.25^2 | delta < 1.25^3 | RMSE | REL |',
        '|---|---|---|---|---|---|',
    ]
    for name, out in [(m, o) for m, _, o, _ in sections] + [('vertical-gradient', sections[0][2])]:
        lines.append(f'| {name} | ' + ' | '.join(f'{v:.4f}' for v in first_row(out, name)) + ' |')
    floor = first_row(sections[0][2], 'vertical-gradient')
    for model, _, out, _ in sections:
        row = first_row(out, model)
        verdict = 'above' if row[0] > floor[0] and row[3] < floor[3] and row[4] < floor[4] else 'not above'
        lines.append(f'\n{model}: {verdict} the vertical-gradient floor on all of delta < 1.25, RMSE and REL '
                     f'(delta < 1.25 {row[0]:.4f} vs {floor[0]:.4f}).')
    lines += ['', 'The outputs these rows are copied from:', '']
    for model, command, out, seconds in sections:
        lines += [f'## {model}', '', f'`{command}` ({seconds:.0f} s)', '', '```', out.rstrip(), '```', '']
    return '\n'.join(lines)


ORDINAL_SET = REPO / 'training' / 'ordinal' / 'ordinal.json.gz'
ORDINAL_SPLITS = ('val', 'test', 'holdout', 'train')
SECTION_SPLITS = ('val', 'test')  # the sections' splits; holdout is kept for judging picks


def ordinal_rows(out):
    """{method: (whdr, pairs, photos)} from an ampi eval depth --ordinal table."""
    rows = {}
    for line in out.splitlines():
        fields = line.split()
        if len(fields) == 4 and fields[0] != 'method':
            rows[fields[0]] = (float(fields[1]), int(fields[2]), int(fields[3]))
    return rows


def ordinal_command(ampi, root, ordinal_set, split, model, threads, *extra):
    """The `ampi eval depth --ordinal` command line that every row of the tables runs."""
    return [ampi, 'eval', 'depth', '--images', str(root), '--ordinal', str(ordinal_set),
            '--split', split, '--model', model, '--threads', str(threads), *extra]


def ordinal_table(ampi, threads):
    import photo_folder
    root = photo_folder.photo_root()
    runs = []
    for split in ORDINAL_SPLITS:
        for model in ('lite', 'heavy'):
            command = ordinal_command(ampi, root, ORDINAL_SET, split, model, threads)
            out, seconds = run(command)
            runs.append((split, model, shown(command).replace(str(root), 'PHOTOS'), out, seconds))
    lines = [
        '# Depth order on real photos (`ampi eval depth --ordinal`)',
        '',
        'Made by `AMPI_PHOTO_ROOT=training/data_cache/photos /usr/bin/python3 eval/make_tables.py',
        'ordinal --ampi AMPI`: the bundled networks on the real-photo ordinal set',
        '(`training/ordinal/`, point pairs labelled by looking at the photos of',
        "`../shared/data/photos` and the archive's training photos, `training/archive_photos.py`;",
        'PHOTOS below is the root that holds both). WHDR is the share of pairs labelled A or',
        'B nearer whose order the disparity gets wrong, a tie counting half; lower is better.',
        '`vertical-gradient` (lower = nearer) and `constant` are the guesses a network must beat.',
        'The validation photos (every fifth of each folder) are never trained on: their pairs of',
        'rounds 1, 2, 4, 7 and 9 (`val`) pick the best of a training run, those of rounds 3, 5, 6,',
        "8 and 10-23 (`test`) never pick anything; but the same photos picked round after round, so",
        '`holdout` (every second archive photo of each of the two groups of packages added after',
        'every bundled file was made, `training/photo_folder.py`) is the one part no choice has',
        "seen: never trained on, never picked on, scored only to judge a pick. The training",
        "photos' pairs are in the ranking",
        "loss (those of the rounds each file trained on: `training/DEPTH.md`), so their row",
        'mostly shows how well it is fitted. `-snapped` scores the map `ampi run` slices, the',
        "network's disparity with its depth edges snapped to the photo (`slicing/depth_edges.h`).",
        '',
        '| split | method | WHDR | pairs | photos |',
        '|---|---|---:|---:|---:|',
    ]
    for split in ORDINAL_SPLITS:
        split_runs = [r for r in runs if r[0] == split]
        rows = {name: row for _, m, _, out, _ in split_runs for name, row in ordinal_rows(out).items()
                if name in (m, f'{m}-snapped')}
        guesses = ordinal_rows(split_runs[0][3])
        rows.update({g: guesses[g] for g in ('vertical-gradient', 'constant')})
        lines += [f'| {split} | {m} | {w:.4f} | {n} | {p} |' for m, (w, n, p) in rows.items()]
    for split, what in (('val', 'validation pairs'), ('test', 'held-out test pairs'),
                        ('holdout', 'holdout photos')):
        scored = {m: ordinal_rows(out) for s, m, _, out, _ in runs if s == split}
        gradient = scored['lite']['vertical-gradient'][0]
        for model in ('lite', 'heavy'):
            whdr = scored[model][model][0]
            gain = 100 * (gradient - whdr)
            side = 'below (better than)' if gain > 0 else 'above (worse than)'
            lines.append(f'\n{model} on the {what}: WHDR {whdr:.4f}, {abs(gain):.1f} points {side} the '
                         f'vertical gradient\'s {gradient:.4f} (the target for lite: at least 10 below).')
    lines += ['', *pair_kind_section(ampi, threads, root)]
    lines += ['', *working_size_section(ampi, threads, root)]
    lines += ['', 'The outputs these rows are copied from:', '']
    for split, model, command, out, seconds in runs:
        lines += [f'## {model}, {split}', '', f'`{command}` ({seconds:.0f} s)', '', '```', out.rstrip(), '```', '']
    return '\n'.join(lines)


def pair_kind_section(ampi, threads, root):
    """WHDR of each bundled network, its map as `ampi run` slices it and the gradient on
    the uniform pairs and on the pairs across image edges, apart, on val and test."""
    whdr = {}
    with tempfile.TemporaryDirectory() as tmp:
        for kind in ('random', 'edge'):
            part = Path(tmp) / f'{kind}.json'
            subprocess.run([sys.executable, str(REPO / 'training' / 'ordinal' / 'pairs.py'), 'subset', str(part),
                            '--kind', kind], check=True, capture_output=True)
            for model in ('lite', 'heavy'):
                for split in SECTION_SPLITS:
                    out, _ = run(ordinal_command(ampi, root, part, split, model, threads))
                    whdr.update({(kind, split, name): row for name, row in ordinal_rows(out).items()})
    methods = ('lite', 'lite-snapped', 'heavy', 'heavy-snapped', 'vertical-gradient')
    return [
        '## Uniform pairs and pairs across edges',
        '',
        'Each round of a photo has five pairs drawn uniformly and two straddling a strong image',
        'edge (`training/ordinal/README.md`). Each part alone: `training/ordinal/pairs.py subset',
        'PART.json --kind random|edge`, then `ampi eval depth --ordinal PART.json` as above.',
        '',
        '| pairs | split | pairs scored | ' + ' | '.join(methods) + ' |',
        '|---|---|---:|' + '---:|' * len(methods),
        *[f'| {kind} | {split} | {whdr[kind, split, "lite"][1]} | '
          + ' | '.join(f'{whdr[kind, split, m][0]:.4f}' for m in methods) + ' |'
          for kind in ('random', 'edge') for split in SECTION_SPLITS],
    ]


WORKING_SIZES = (192, 256, 320, 384, 512)


def working_size_section(ampi, threads, root):
    """WHDR of each bundled network at several long sides (`--working-size`), 256, the one
    it was trained and picked at, among them; on val and test."""
    whdr = {}
    for model in ('lite', 'heavy'):
        for size in WORKING_SIZES:
            for split in SECTION_SPLITS:
                out, _ = run(ordinal_command(ampi, root, ORDINAL_SET, split, model, threads,
                                             '--working-size', str(size)))
                whdr[model, size, split] = ordinal_rows(out)[model][0]
    columns = [(m, s) for m in ('lite', 'heavy') for s in SECTION_SPLITS]
    return [
        '## Working size',
        '',
        'Both networks were trained on 256x192 crops and are run with the long side at 256',
        '(their files\' `depth.working_long_side`). `--working-size N` runs them at another',
        'long side; each cell is the WHDR row of `ampi eval depth --images PHOTOS --ordinal',
        'training/ordinal/ordinal.json.gz --split SPLIT --model MODEL --working-size N`.',
        'A larger working size does not order depth better: each network orders best at the',
        'frame size it was trained at.',
        '',
        '| long side | ' + ' | '.join(f'{m} {s}' for m, s in columns) + ' |',
        '|---:|' + '---:|' * len(columns),
        *[f'| {size} | ' + ' | '.join(f'{whdr[m, size, s]:.4f}' for m, s in columns) + ' |'
          for size in WORKING_SIZES],
    ]


def link_photos(folder, photos, root):
    """The photos as links under folder, keeping each photo's subfolder."""
    for photo in photos:
        link = Path(folder) / photo.relative_to(root)
        link.parent.mkdir(parents=True, exist_ok=True)
        link.symlink_to(photo)


def slicing_rows(out):
    """{(count, method): (planes, ssim, psnr)} from an ampi eval slicing table."""
    rows = {}
    for line in out.splitlines():
        fields = line.split()
        if len(fields) == 5 and fields[0].isdigit() and fields[1] in ('adaptive', 'uniform'):
            rows[(int(fields[0]), fields[1])] = tuple(float(x) for x in fields[2:])
    return rows


def verdict_of(out):
    lines = [l for l in out.splitlines() if l.startswith('adaptive >= uniform at every count')]
    return lines[0] if lines else '?'


TUNING_TEAR_PENALTIES = ('0', '100', '1000')  # --tear-penalty values compared on the tuning photos


def adaptive_minus_uniform(runs, label):
    """Markdown rows: per run and count, adaptive's planes and its SSIM and PSNR above uniform's."""
    lines = [f'| {label} | count | planes | SSIM difference | PSNR difference (dB) |', '|---|---:|---:|---:|---:|']
    for value, out, _ in runs:
        rows = slicing_rows(out)
        for count in sorted({c for c, _ in rows}):
            a, u = rows[(count, 'adaptive')], rows[(count, 'uniform')]
            lines.append(f'| {value} | {count} | {a[0]:.2f} | {a[1] - u[1]:+.4f} | {a[2] - u[2]:+.3f} |')
    return lines


def penalty_effect(tuning):
    """How adaptive's mean PSNR changes, count by count, from the first tuning run to each other one."""
    base = slicing_rows(tuning[0][1])
    parts = []
    for penalty, out, _ in tuning[1:]:
        rows = slicing_rows(out)
        changes = ', '.join(f'{rows[(c, "adaptive")][2] - base[(c, "adaptive")][2]:+.3f} dB at {c}'
                            for c, m in sorted(base) if m == 'adaptive')
        parts.append(f"a penalty of {penalty} changes adaptive's mean PSNR by {changes}")
    return '; '.join(parts)


def slicing_table(ampi, threads, scene_count, extra):
    import photo_folder
    root = photo_folder.photo_root()
    photos = photo_folder.list_photos('val')
    # Where the tear penalty was chosen: training photos only, never the validation ones.
    tuning_photos = photo_folder.list_photos('train')[5::10]
    eval_slicing = [ampi, 'eval', 'slicing', '--threads', str(threads)] + extra
    with tempfile.TemporaryDirectory(prefix='ampi-eval-slicing-') as tmp:
        val_dir, tuning_dir = Path(tmp) / 'val', Path(tmp) / 'tuning'
        link_photos(val_dir, photos, root)
        link_photos(tuning_dir, tuning_photos, root)
        command = eval_slicing + ['--images', val_dir]
        out, seconds = run(command)
        command = shown(command).replace(str(val_dir), 'VAL_PHOTOS')
        no_snap_out, no_snap_seconds = run(eval_slicing + ['--images', val_dir, '--no-edge-snap'])
        paper_flags = ['--slicer', 'paper']
        guard_flags = paper_flags + ['--min-plane-share', '0.5']
        paper_out, paper_seconds = run(eval_slicing + ['--images', val_dir] + paper_flags)
        guard_out, guard_seconds = run(eval_slicing + ['--images', val_dir] + guard_flags)
        tuning = []
        for penalty in TUNING_TEAR_PENALTIES:
            tuning_out, tuning_seconds = run(eval_slicing + ['--images', tuning_dir, '--tear-penalty', penalty])
            tuning.append((penalty, tuning_out, tuning_seconds))
        example = val_dir / photos[0].relative_to(root)
        depth_png = Path(tmp) / 'example_depth.png'
        run([ampi, 'depth', example, '-o', depth_png])
        example_cuts = {kind: run([ampi, 'slice', depth_png, '--max-planes', '4'] + flag)[0]
                        for kind, flag in (('the paper\'s cuts (--slicer paper)', paper_flags),
                                           ('optimal cuts (default)', []), ('uniform', ['--uniform']))}
        example_name = str(photos[0].relative_to(root))
    with tempfile.TemporaryDirectory(prefix='ampi-eval-slicing-scenes-') as tmp:
        write_scenes(tmp, scene_count)
        exact_command = eval_slicing + ['--images', f'{tmp}/images', '--depth-dir', f'{tmp}/reference']
        exact_out, exact_seconds = run(exact_command)
        exact_command = shown(exact_command).replace(tmp, 'SCENES')
    fenced = lambda text: ['```', text.rstrip(), '```']  # noqa: E731
    lines = [
        "# The paper's Table 3 on the validation photos (`ampi eval slicing`)",
        '',
        'Made by `/usr/bin/python3 eval/make_tables.py slicing --ampi AMPI`: VAL_PHOTOS holds the',
        f'{len(photos)} validation photos (every tenth photo by sorted name of each folder of',
        '`../shared/data/photos`, `training/photo_folder.py` `photo_split`), then:',
        '',
        f'`{command}` ({seconds:.0f} s)',
        '',
        *fenced(out),
        '',
        'Protocol (`ampi eval slicing --help`, `eval/slicing_eval.h`): per photo and maximum plane',
        'count, an adaptive MPI, a uniform MPI with the number of planes adaptive made, and a',
        'densely sampled uniform reference MPI, all from the bundled lite depth network and',
        'push-pull inpainting, rendered at the same target poses; SSIM and PSNR against the',
        'reference\'s views. The paper (section "Evaluation metrics") compares with "a densely',
        'sampled MPI projected to the target view point" where it has no second view, as here;',
        'its Table 3 itself uses RealEstate10K target frames, so the numbers are not comparable',
        'to the paper\'s (it reports SSIM 0.67-0.68, PSNR 18.7-19.0 dB).',
        '',
        'Adaptive here is the default slicer, `--slicer optimal` (`slicing/optimal_cuts.h`): the',
        'paper\'s pipeline (bilateral filter, Canny edges, eroded borders, edge-aware histogram,',
        'transition index, greedy selection with its threshold) decides how many planes a photo',
        'gets; the cuts are then placed by exact dynamic programming over the 256 disparity',
        'levels to minimise the planes\' summed squared disparity error over all pixels (each',
        'pixel is drawn at its plane\'s mean disparity, so this is what moves it away from the',
        'dense reference). That is optimal 1-D quantisation (Jenks natural breaks, solved',
        'exactly): uniform intervals with the same count are one of the candidates, so their',
        'squared disparity error is never lower (`tests/slicing/test_optimal_cuts.cpp`).',
        '',
        'Depth edges follow the photo here, as in `ampi run` (`slicing/depth_edges.h`): every MPI',
        'is cut from the map snapped to the photo\'s colour edges, with the layer borders',
        'feathered at them. The same without that, the map enlarged bilinearly as before (each',
        'table is against its own dense reference: with snapped edges every MPI, the reference',
        'too, opens real gaps at object borders where a soft map stretched the object over',
        'them, so the views differ more between plane counts and the scores are lower):',
        '',
        f'`{command} --no-edge-snap` ({no_snap_seconds:.0f} s)',
        '',
        *fenced(no_snap_out),
        '',
        '## The paper\'s rule exactly',
        '',
        f'`{command} {shown(paper_flags)}` ({paper_seconds:.0f} s)',
        '',
        *fenced(paper_out),
        '',
        'And with the guard that was the default before the optimal slicer (a transition is',
        'taken only if every plane keeps more than 0.5 / N of the depth histogram):',
        '',
        f'`{command} {shown(guard_flags)}` ({guard_seconds:.0f} s)',
        '',
        *fenced(guard_out),
        '',
        '## Why the paper\'s cuts lose here',
        '',
        f'The planes of the first validation photo, `{example_name}`, with the lite network\'s depth',
        f'(`ampi depth VAL_PHOTOS/{example_name} -o D.png`, then `ampi slice D.png --max-planes 4`',
        'with `--slicer paper`, with the default, and with `--uniform`):',
        '',
        '```',
    ]
    for kind, cuts in example_cuts.items():
        lines += [f'{kind}:', cuts.rstrip()]
    lines += [
        '```',
        '',
        'The transition index divides the histogram\'s Laplacian by the histogram itself, so it is',
        'largest where few pixels are: on a smooth depth map the sparse ends draw the cuts, leaving',
        'slivers of a few hundred pixels while one plane holds most of the pixels over a wide',
        'disparity interval. A dense reference penalises exactly that (every pixel of a plane',
        'moves with the plane\'s mean disparity). The optimal cuts keep the paper\'s count and',
        'spend the planes where the pixels are.',
        '',
        '## The tear penalty',
        '',
        'A cut through a continuous surface also opens a crack along it when the camera moves;',
        'the paper\'s edge-aware histogram h (depth edges left out) measures how much surface a',
        'cut at a level goes through, and the optimal slicer can charge for it',
        '(`SlicingParams::tear_penalty`, `--tear-penalty P`: P squared levels per pixel of h at',
        f'the cut). It was chosen on {len(tuning_photos)} training photos (every tenth of the training',
        'split, from the sixth; never the validation photos above), with the same command and',
        f'`--tear-penalty` {", ".join(TUNING_TEAR_PENALTIES)}:',
        '',
    ]
    for penalty, tuning_out, tuning_seconds in tuning:
        lines += [f'`--tear-penalty {penalty}` ({tuning_seconds:.0f} s):', '', *fenced(tuning_out), '']
    lines += [
        'Adaptive minus uniform, and the mean number of planes, per penalty and count:',
        '',
        *adaptive_minus_uniform(tuning, '--tear-penalty'),
        '',
        f'The default is {TUNING_TEAR_PENALTIES[0]}, no penalty: {penalty_effect(tuning)}.',
        '',
        '## The same with exact depth',
        '',
        f'Whether the depth or the slicing is at fault: {scene_count} synthetic validation scenes',
        f'(`training/make_eval_scenes.py SCENES --count {scene_count}`, as for RESULTS-depth-eval.md)',
        'sliced with their exact disparity instead of the network\'s (`--depth-dir`):',
        '',
        f'`{exact_command}` ({exact_seconds:.0f} s)',
        '',
        *fenced(exact_out),
        '',
        'Target: adaptive at or above uniform at every count. Result on the validation',
        f'photos: {verdict_of(out)}; without edge snapping: {verdict_of(no_snap_out)};',
        f'with the paper\'s rule exactly: {verdict_of(paper_out)};',
        f'with exact depth: {verdict_of(exact_out)}.',
        '',
    ]
    return '\n'.join(lines)


SCENE_NAMES = ('disk', 'pole', 'person', 'two-objects')


def after_flawed(row):
    """Whether a row of ampi eval edges has wrong pixels or fringe after snapping."""
    fields = row.split()
    wrong_after = float(fields[5].split('/')[1])
    fringe_after = int(fields[6].split('/')[1])
    return wrong_after > 0 or fringe_after > 0


def edges_table(ampi, threads):
    import photo_folder
    root = photo_folder.photo_root()
    val = photo_folder.list_photos('val')
    # The first validation photo of three folders: textures from photos no network trained on.
    textures = []
    for folder in ('kodak24', 'urban100', 'sun80'):
        textures += [p for p in val if p.relative_to(root).parts[0] == folder][:1]
    command = [ampi, 'eval', 'edges', '--threads', str(threads)]
    out, seconds = run(command)
    fenced = lambda text: ['```', text.rstrip(), '```']  # noqa: E731
    lines = [
        '# Objects kept whole when the camera moves (`ampi eval edges`)',
        '',
        'Made by `/usr/bin/python3 eval/make_tables.py edges --ampi AMPI`. Scenes of textured',
        'fronto-parallel surfaces whose new views are known exactly (`eval/edge_eval.h`): a disk',
        'over a background (the README\'s scene), a thin pole, a person-like silhouette, two objects',
        'at different depths; 640x480, disparity 1 (and 0.6) over 0.25. Each scene\'s disparity map',
        'is made soft (reduced 4 or 8 times and enlarged bilinearly, as a network\'s map is; or',
        'hard) and made into an MPI as `ampi run --depth` does (8 planes at most, the inpainting',
        'network), before (`--no-edge-snap`: the map sliced as it is) and after (depth edges',
        'snapped to the photo, layer borders feathered), then rendered at four poses. Columns:',
        'how far the object moves against the background (px), planes made, the share of object',
        'pixels wrong (the MPI shows under half of the right surface there; traced by rendering',
        'the MPI with surface labels instead of colours), fringe (uncovered background showing',
        'a nearer surface) and holes (pixels no layer covers: uncovered background beyond the',
        'filled margin, 25 px at this size, which the 44-55 px poses exceed). The wrong share is',
        'over the pixels the exact view shows an object at, so it passes 100% where a thin object',
        '(the pole) leaves copies of itself over the background.',
        '',
        f'`{shown(command)}` ({seconds:.0f} s), built-in noise textures:',
        '',
        *fenced(out),
        '',
        'The same scenes textured with crops of validation photos (`--texture`):',
        '',
    ]
    for photo in textures:
        texture_command = command + ['--texture', photo]
        texture_out, texture_seconds = run(texture_command)
        name = photo.relative_to(root)
        header, *rows = texture_out.splitlines()
        flawed = [r for r in rows if r.split()[:1] and r.split()[0] in SCENE_NAMES and after_flawed(r)]
        verdicts = [r for r in rows if r.startswith(('softness', '  target', 'poses', 'target'))]
        lines += [f'`{shown(command)} --texture {name}` ({texture_seconds:.0f} s); the rows with anything',
                  'wrong after, then the verdicts:', '', *fenced('\n'.join([header] + flawed + verdicts)), '']
    return '\n'.join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('table', choices=['depth', 'slicing', 'ordinal', 'edges'])
    parser.add_argument('--ampi', required=True, help='the ampi program')
    parser.add_argument('--threads', type=int, default=2)
    parser.add_argument('--count', type=int, default=50, help='synthetic scenes (default 50)')
    parser.add_argument('--out', help='table file (default bench/RESULTS-depth-eval.md, -slicing.md, -ordinal.md or -edges.md)')
    args, extra = parser.parse_known_args(argv)
    ampi = str(Path(args.ampi).resolve())
    tables = {'depth': ('depth-eval', lambda: depth_table(ampi, args.count, args.threads)),
              'slicing': ('slicing', lambda: slicing_table(ampi, args.threads, args.count, extra)),
              'ordinal': ('ordinal', lambda: ordinal_table(ampi, args.threads)),
              'edges': ('edges', lambda: edges_table(ampi, args.threads))}
    name, make = tables[args.table]
    text = make()
    out = Path(args.out) if args.out else REPO / 'bench' / f'RESULTS-{name}.md'
    out.write_text(text)
    print(f'wrote {out}')
    return 0


if __name__ == '__main__':
    sys.exit(main())

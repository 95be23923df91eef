#!/usr/bin/env python3
"""Judges a candidate depth weight file against the bundled one by bars fixed before the
candidate existed (training/DEPTH.md writes each round's rule down before its run).

    AMPI_PHOTO_ROOT=training/data_cache/photos /usr/bin/python3 training/judge_candidate.py \\
        --candidate CAND.ampw --against weights/depth_heavy.ampw \\
        --holdout-better 0.5 --test-worse 0 --synthetic-lower 1 [--ampi build/ampi] [--threads 2]

Both files are scored by the same build on the same day: `ampi eval depth --ordinal` on the
ordinal set's `holdout`, `test` and `val` parts, and `ampi eval depth` on the 50 synthetic
validation scenes of `eval/make_tables.py depth`. The bars, in points (hundredths):
  holdout    the candidate's WHDR at least --holdout-better below the bundled file's
  test       the candidate's WHDR at most --test-worse above it
  synthetic  the candidate's delta < 1.25 at most --synthetic-lower below it
`val` is reported and bars nothing: every pick so far was made on it. Prints a Markdown
table and each bar's verdict; exits 0 when every bar holds, 3 when one fails, 1 on error.
The scores are compared as ampi prints them (four decimals), so a reader of the table can
check each verdict by hand.
"""

import argparse
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / 'eval'))
import make_tables  # noqa: E402

SYNTHETIC_SCENES = 50     # as eval/make_tables.py depth
SPLITS = ('holdout', 'test', 'val')
BAR_FAILED = 3


def ordinal_whdr(ampi, root, weights, split, threads):
    command = [ampi, 'eval', 'depth', '--images', str(root), '--ordinal', str(make_tables.ORDINAL_SET),
               '--split', split, '--weights', str(weights), '--threads', str(threads)]
    rows = make_tables.ordinal_rows(make_tables.run(command)[0])
    return rows[Path(weights).name][0]


def synthetic_delta(ampi, scenes, weights, threads):
    command = [ampi, 'eval', 'depth', '--images', f'{scenes}/images', '--reference', f'{scenes}/reference',
               '--weights', str(weights), '--threads', str(threads)]
    return make_tables.first_row(make_tables.run(command)[0], Path(weights).name)[0]


def scores_of(ampi, root, scenes, weights, threads):
    """{'holdout': WHDR, 'test': WHDR, 'val': WHDR, 'synthetic': delta < 1.25} of one file."""
    scores = {split: ordinal_whdr(ampi, root, weights, split, threads) for split in SPLITS}
    scores['synthetic'] = synthetic_delta(ampi, scenes, weights, threads)
    return scores


def ten_thousandths(value):
    return round(value * 10000)


def verdicts(candidate, against, holdout_better, test_worse, synthetic_lower):
    """[(bar, holds, why)] for the three bars; scores as scores_of returns them, bars in points."""
    def points(p):
        return round(p * 100)   # a point is 100 ten-thousandths

    cand = {k: ten_thousandths(v) for k, v in candidate.items()}
    base = {k: ten_thousandths(v) for k, v in against.items()}
    limits = {
        'holdout': (base['holdout'] - points(holdout_better), '<='),
        'test': (base['test'] + points(test_worse), '<='),
        'synthetic': (base['synthetic'] - points(synthetic_lower), '>='),
    }
    result = []
    for bar, (limit, sense) in limits.items():
        holds = cand[bar] <= limit if sense == '<=' else cand[bar] >= limit
        result.append((bar, holds, f'{cand[bar] / 10000:.4f} {sense} {limit / 10000:.4f}'))
    return result


def report(candidate_name, against_name, candidate, against, bars):
    lines = ['| weights | `holdout` WHDR | `test` WHDR | `val` WHDR (no bar) | synthetic delta < 1.25 |',
             '|---|---:|---:|---:|---:|']
    for name, scores in ((against_name, against), (candidate_name, candidate)):
        lines.append(f'| {name} | ' + ' | '.join(f'{scores[k]:.4f}' for k in (*SPLITS, 'synthetic')) + ' |')
    lines.append('')
    for bar, holds, why in bars:
        lines.append(f'- {bar}: {"holds" if holds else "FAILS"} ({why})')
    passed = all(holds for _, holds, _ in bars)
    lines.append(f'\n{candidate_name}: {"every bar holds" if passed else "a bar fails: not to be bundled"}')
    return '\n'.join(lines), passed


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--candidate', required=True, type=Path)
    parser.add_argument('--against', required=True, type=Path, help='the bundled weight file')
    parser.add_argument('--holdout-better', required=True, type=float, help='points')
    parser.add_argument('--test-worse', required=True, type=float, help='points')
    parser.add_argument('--synthetic-lower', required=True, type=float, help='points')
    parser.add_argument('--ampi', default=REPO / 'build' / 'ampi', type=Path)
    parser.add_argument('--threads', type=int, default=2)
    args = parser.parse_args(argv)
    for path in (args.candidate, args.against, args.ampi):
        if not path.is_file():
            sys.exit(f'judge_candidate.py: {path}: no such file')

    import photo_folder
    root = photo_folder.photo_root()
    with tempfile.TemporaryDirectory(prefix='ampi-judge-') as scenes:
        make_tables.write_scenes(scenes, SYNTHETIC_SCENES)
        against = scores_of(args.ampi, root, scenes, args.against, args.threads)
        candidate = scores_of(args.ampi, root, scenes, args.candidate, args.threads)
    bars = verdicts(candidate, against, args.holdout_better, args.test_worse, args.synthetic_lower)
    text, passed = report(str(args.candidate), str(args.against), candidate, against, bars)
    print(text)
    return 0 if passed else BAR_FAILED


if __name__ == '__main__':
    sys.exit(main())

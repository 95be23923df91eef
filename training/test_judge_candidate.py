"""Tests of training/judge_candidate.py's bars: each holds exactly up to its limit, in the
four decimals ampi prints, and fails one step past it."""
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import judge_candidate  # noqa: E402

BUNDLED = {'holdout': 0.1082, 'test': 0.1257, 'val': 0.1117, 'synthetic': 0.5464}


def bars_of(candidate, holdout_better=0.5, test_worse=0.0, synthetic_lower=1.0):
    return {bar: holds for bar, holds, _ in
            judge_candidate.verdicts(candidate, BUNDLED, holdout_better, test_worse, synthetic_lower)}


class Bars(unittest.TestCase):
    def test_each_bar_holds_at_its_limit(self):
        at_limits = {'holdout': 0.1032, 'test': 0.1257, 'val': 0.5, 'synthetic': 0.5364}
        self.assertEqual(bars_of(at_limits), {'holdout': True, 'test': True, 'synthetic': True})

    def test_each_bar_fails_one_step_past_its_limit(self):
        past = {'holdout': 0.1033, 'test': 0.1258, 'val': 0.0, 'synthetic': 0.5363}
        self.assertEqual(bars_of(past), {'holdout': False, 'test': False, 'synthetic': False})

    def test_val_bars_nothing_and_test_allowance_counts(self):
        candidate = {'holdout': 0.0900, 'test': 0.1307, 'val': 0.9, 'synthetic': 0.60}
        self.assertEqual(bars_of(candidate, test_worse=0.5), {'holdout': True, 'test': True, 'synthetic': True})
        self.assertFalse(bars_of(candidate, test_worse=0.4)['test'])

    def test_report_says_not_to_bundle_when_a_bar_fails(self):
        candidate = dict(BUNDLED)
        bars = judge_candidate.verdicts(candidate, BUNDLED, 0.5, 0.0, 1.0)
        text, passed = judge_candidate.report('cand.ampw', 'depth_heavy.ampw', candidate, BUNDLED, bars)
        self.assertFalse(passed)
        self.assertIn('- holdout: FAILS (0.1082 <= 0.1032)', text)
        self.assertIn('not to be bundled', text)

    def test_missing_file_is_one_line_error(self):
        with self.assertRaises(SystemExit) as stop:
            judge_candidate.main(['--candidate', '/nonexistent.ampw', '--against', '/nonexistent2.ampw',
                                  '--holdout-better', '0.5', '--test-worse', '0', '--synthetic-lower', '1'])
        self.assertEqual(str(stop.exception), 'judge_candidate.py: /nonexistent.ampw: no such file')


if __name__ == '__main__':
    unittest.main()

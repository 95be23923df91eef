"""Tests of eval/depth_ceiling.py's three alignments."""
import sys
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import depth_ceiling  # noqa: E402


class Alignments(unittest.TestCase):
    def setUp(self):
        self.reference = np.random.default_rng(5).uniform(0.02, 1.0, (40, 60))

    def test_an_affine_prediction_is_perfect_every_way(self):
        self.assertEqual(depth_ceiling.scores(3.0 * self.reference - 1.0, self.reference), [1.0, 1.0, 1.0])

    def test_an_increasing_warp_loses_only_calibration(self):
        median_std, least_squares, rank_matched = depth_ceiling.scores(np.log(self.reference), self.reference)
        self.assertEqual(rank_matched, 1.0)
        self.assertLess(median_std, 0.9)
        self.assertLess(least_squares, 0.9)

    def test_a_shuffled_prediction_loses_ordering(self):
        shuffled = np.random.default_rng(6).permutation(self.reference.ravel()).reshape(self.reference.shape)
        self.assertLess(depth_ceiling.scores(shuffled, self.reference)[2], 0.5)

    def test_unmeasured_pixels_are_left_out(self):
        reference = self.reference.copy()
        reference[:10] = 0                      # the sky: no measurement
        prediction = reference.copy()
        prediction[:10] = 100.0                 # wildly wrong there, ignored
        self.assertEqual(depth_ceiling.scores(prediction, reference), [1.0, 1.0, 1.0])
        with self.assertRaisesRegex(ValueError, 'no valid'):
            depth_ceiling.scores(prediction, np.zeros_like(reference))


if __name__ == '__main__':
    unittest.main()

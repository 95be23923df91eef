"""Tests of the validation metrics logged by train_depth.py (aligned_metrics)."""
import sys
import unittest
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import train_depth  # noqa: E402


def ramp_scene(seed: int) -> torch.Tensor:
    g = torch.Generator().manual_seed(seed)
    return torch.rand(2, 1, 24, 32, generator=g) * 5 + 0.2


class AlignedMetricsTest(unittest.TestCase):
    def test_a_prediction_equal_up_to_scale_and_shift_is_perfect(self):
        target = ramp_scene(1)
        m = train_depth.aligned_metrics(3.0 * target - 7.0, target)
        self.assertAlmostEqual(m["delta1.25"], 1.0)
        self.assertAlmostEqual(m["delta1.25^3"], 1.0)
        self.assertLess(m["rmse"], 1e-4)
        self.assertLess(m["rel"], 1e-5)

    def test_an_unrelated_prediction_scores_badly(self):
        target, noise = ramp_scene(2), ramp_scene(3)
        m = train_depth.aligned_metrics(noise, target)
        self.assertLess(m["delta1.25"], 0.6)
        self.assertGreater(m["rmse"], 1.0)

    def test_thresholds_are_nested(self):
        target = ramp_scene(4)
        m = train_depth.aligned_metrics(target + 0.8 * ramp_scene(5), target)
        self.assertLessEqual(m["delta1.25"], m["delta1.25^2"])
        self.assertLessEqual(m["delta1.25^2"], m["delta1.25^3"])
        self.assertLess(m["delta1.25"], 1.0)


if __name__ == "__main__":
    unittest.main()

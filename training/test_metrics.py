"""Tests of the validation metrics logged by train_depth.py (aligned_metrics) and of the
depth losses (losses.py)."""
import sys
import unittest
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import losses  # noqa: E402
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


class DepthLossTest(unittest.TestCase):
    def outputs(self, disparity):
        """The network's four outputs for a prediction equal to `disparity`."""
        return [torch.nn.functional.avg_pool2d(disparity, 2 ** s) if s else disparity for s in (3, 2, 1, 0)]

    def test_the_invariant_loss_ignores_scale_and_shift_the_paper_loss_does_not(self):
        target = ramp_scene(2)
        affine = self.outputs(3.0 * target + 5.0)
        self.assertLess(float(losses.depth_loss(affine, target, invariant=True)[0]), 1e-4)
        self.assertGreater(float(losses.depth_loss(affine, target)[0]), 1.0)
        self.assertLess(float(losses.depth_loss(self.outputs(losses.normalise_target(target)), target)[0]), 1e-4)

    def test_the_invariant_loss_sees_a_flipped_map(self):
        target = ramp_scene(3)
        self.assertGreater(float(losses.depth_loss(self.outputs(-target), target, invariant=True)[0]), 1.0)

    def test_normalised_maps_have_median_zero_and_the_set_spread(self):
        x = losses.normalise_median_mad(ramp_scene(4) ** 2)
        for image in x.flatten(1):
            self.assertAlmostEqual(float(image.median()), 0.0, places=5)
            self.assertAlmostEqual(float(image.abs().mean()), losses.INVARIANT_SPREAD, places=4)


class WeightAverageTest(unittest.TestCase):
    def test_moves_each_float_by_one_minus_decay_and_copies_counters(self):
        model = torch.nn.Sequential(torch.nn.Linear(3, 2), torch.nn.BatchNorm1d(2))
        average = train_depth.WeightAverage(model, decay=0.75)
        before = {k: v.clone() for k, v in average.model.state_dict().items()}
        with torch.no_grad():
            for p in model.parameters():
                p.add_(4.0)
            model[1].running_mean.add_(8.0)
            model[1].num_batches_tracked.fill_(5)
        average.update(model)
        after = average.model.state_dict()
        for name, p in model.named_parameters():
            torch.testing.assert_close(after[name], before[name] + 1.0)   # a quarter of the way
        torch.testing.assert_close(after["1.running_mean"], before["1.running_mean"] + 2.0)
        self.assertEqual(int(after["1.num_batches_tracked"]), 5)
        self.assertFalse(any(p.requires_grad for p in average.model.parameters()))


if __name__ == "__main__":
    unittest.main()

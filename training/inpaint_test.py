"""Unit tests of the inpainting network's Python side: the push-pull port, the residual
generator's starting point, the export round trip and the training data's slicing.
Run: /usr/bin/python3 training/inpaint_test.py"""
import os
import sys
import tempfile
import unittest

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import export_inpaint  # noqa: E402
import inpaint_data  # noqa: E402
import inpaint_model as im  # noqa: E402
import inpaint_push_pull as pp  # noqa: E402


class PushPullTest(unittest.TestCase):
    def test_resampling_weights_are_averages(self):
        for src, dst in ((7, 4), (64, 32), (3, 2), (1, 1)):
            np.testing.assert_allclose(pp.area_matrix(src, dst).sum(1), 1, atol=1e-6)
        for src, dst in ((4, 7), (2, 3), (1, 2), (32, 64)):
            np.testing.assert_allclose(pp.linear_matrix(src, dst).sum(1), 1, atol=1e-6)

    def test_constant_image_fills_constant_and_keeps_known(self):
        rng = np.random.default_rng(0)
        image = np.full((23, 31, 3), 77, np.uint8)
        known = rng.random((23, 31)) > 0.6
        image[~known] = 0  # what a method sees in the hole
        out = pp.push_pull_fill(image, known, ~known)
        self.assertTrue((out == 77).all())
        noise = rng.integers(0, 256, (23, 31, 3)).astype(np.uint8)
        out = pp.push_pull_fill(noise, known, ~known)
        self.assertTrue((out[known] == noise[known]).all())

    def test_nothing_known_changes_nothing(self):
        image = np.full((8, 8, 3), 5, np.uint8)
        self.assertTrue((pp.push_pull_fill(image, np.zeros((8, 8), bool), np.ones((8, 8), bool)) == 5).all())


class HarmonicFillTest(unittest.TestCase):
    def test_linear_ramp_is_continued_into_a_hole(self):
        yy, xx = np.mgrid[0:40, 0:50]
        image = np.stack([20 + 3 * xx, 200 - 2 * yy, 60 + xx + yy], -1).astype(np.uint8)
        known = (yy - 20) ** 2 + (xx - 20) ** 2 > 100  # an interior disc is unknown
        noisy = image.copy()
        noisy[~known] = np.random.default_rng(0).integers(0, 256, (int((~known).sum()), 3))
        out = pp.harmonic_fill(noisy, known, ~known)
        err = np.abs(out.astype(int) - image.astype(int))
        self.assertLessEqual(err.max(), 1)  # a linear ramp is harmonic: exact up to rounding
        pushed = np.abs(pp.push_pull_fill(noisy, known, ~known).astype(int) - image.astype(int))
        self.assertGreater(pushed.max(), 3)  # what the relaxation adds

    def test_constant_and_nothing_known(self):
        rng = np.random.default_rng(1)
        image = np.full((9, 13, 3), 41, np.uint8)
        known = rng.random((9, 13)) > 0.7
        self.assertTrue((pp.harmonic_fill(image, known, ~known) == 41).all())
        none = np.zeros((9, 13), bool)
        self.assertTrue((pp.harmonic_fill(image, none, ~none) == image).all())


class ResidualGeneratorTest(unittest.TestCase):
    def test_untrained_generator_returns_push_pull(self):
        torch.manual_seed(0)
        g = im.InpaintGenerator()
        self.assertEqual(g.version, 2)
        rgb = torch.rand(2, 3, 32, 40) * 2 - 1
        hole = (torch.rand(2, 1, 32, 40) > 0.5).float()
        self.assertTrue(torch.equal(g(rgb, hole), rgb))

    def test_trained_residual_only_touches_the_hole(self):
        torch.manual_seed(0)
        g = im.InpaintGenerator()
        torch.nn.init.normal_(g.convs[-1].weight, std=0.1)
        rgb = torch.rand(1, 3, 32, 40) * 2 - 1
        hole = (torch.rand(1, 1, 32, 40) > 0.5).float()
        out = g(rgb, hole)
        known = hole.expand_as(rgb) == 0
        self.assertTrue(torch.equal(out[known], rgb[known]))
        self.assertFalse(torch.equal(out[~known], rgb[~known]))


class ExportTest(unittest.TestCase):
    def test_import_inverts_export(self):
        torch.manual_seed(3)
        g = im.InpaintGenerator()
        for p in g.parameters():
            torch.nn.init.normal_(p, std=0.1)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "g.ampw")
            export_inpaint.export(g, path)
            back = export_inpaint.import_ampw(path)
        self.assertEqual(back.residual, g.residual)
        for (name, a), (_, b) in zip(g.state_dict().items(), back.state_dict().items()):
            self.assertTrue(torch.equal(a, b), name)


class SlicingTest(unittest.TestCase):
    def test_every_plane_keeps_its_share(self):
        """The numpy slicer keeps the C++ slicer's guard: each plane above
        min_plane_share / max_planes of the histogram."""
        rng = np.random.default_rng(1)
        least = inpaint_data.SLICE_MIN_PLANE_SHARE / inpaint_data.SLICE_MAX_PLANES
        for _ in range(10):
            disparity = np.cumsum(rng.normal(size=(90, 120)), axis=0) + rng.normal(size=(90, 120))
            h = inpaint_data.slicing_histogram(inpaint_data.normalise_levels(disparity))
            cuts = [0] + inpaint_data.select_transitions(h) + [len(h)]
            for lo, hi in zip(cuts, cuts[1:]):
                self.assertGreater(h[lo:hi].sum(), least)

    def test_a_sparse_end_is_not_cut_off(self):
        h = np.zeros(256)
        h[3:6] = 0.001  # a few pixels at the far end
        h[40:120] = 1.0
        h[150:230] = 1.0
        h /= h.sum()
        cuts = inpaint_data.select_transitions(h)
        self.assertTrue(any(120 <= c <= 150 for c in cuts))  # the gap between the clusters
        # The paper's rule alone would also cut at 39, leaving the few far pixels a plane.
        self.assertTrue(all(h[:c].sum() > 0.01 for c in cuts))


if __name__ == "__main__":
    unittest.main()

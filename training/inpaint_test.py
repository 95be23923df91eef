"""Unit tests of the inpainting network's Python side: the push-pull port and the
residual generator's starting point. Run: /usr/bin/python3 training/inpaint_test.py"""
import os
import sys
import unittest

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
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


if __name__ == "__main__":
    unittest.main()

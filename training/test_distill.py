"""Tests of the pseudo-ground-truth builder with stand-in teachers (run by ctest:
`/usr/bin/python3 -m unittest training/test_distill.py`). Small squares keep it fast; the
paper's resolutions are checked as the default."""
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import distill  # noqa: E402

SMALL = (32, 48, 64, 80, 96)
SEED = 1234


def test_photo(height=40, width=56, seed=SEED):
    """A left-right asymmetric photo: red rises to the right, green is noise."""
    rng = np.random.default_rng(seed)
    rgb = np.zeros((height, width, 3), np.float32)
    rgb[..., 0] = np.linspace(0.0, 1.0, width)[None, :] ** 2
    rgb[..., 1] = rng.random((height, width))
    return rgb


def red_teacher(rgb):
    """Disparity = red channel, with a scale and shift that change with the input size,
    as real teachers' do."""
    side = rgb.shape[0]
    return rgb[..., 0] * (0.01 * side) + side


class PseudoGroundTruth(unittest.TestCase):
    def test_defaults_are_the_papers_resolutions(self):
        self.assertEqual(distill.PAPER_RESOLUTIONS, (512, 768, 1024, 1600, 1920))

    def test_ten_predictions_at_the_largest_resolution(self):
        calls = []

        def teacher(rgb):
            calls.append(rgb.shape)
            return rgb[..., 0]

        stack = distill.ensemble_predictions(test_photo(), teacher, SMALL)
        self.assertEqual(stack.shape, (10, 96, 96))
        self.assertEqual(sorted(calls), sorted([(s, s, 3) for s in SMALL for _ in range(2)]))

    def test_recovers_content_despite_scale_shift_and_flips(self):
        rgb = test_photo()
        label = distill.pseudo_ground_truth(rgb, red_teacher, SMALL)
        self.assertEqual(label.shape, rgb.shape[:2])
        expected = rgb[..., 0] / rgb[..., 0].max()
        err = np.abs(label - expected).max()
        # The residue is the bilinear round trip through the squares, largest at the edges.
        self.assertLess(err, 0.05, f"seed {SEED}: max error {err}")
        self.assertAlmostEqual(float(label.min()), 0.0, places=6)
        self.assertAlmostEqual(float(label.max()), 1.0, places=6)

    def test_mirrored_predictions_are_flipped_back(self):
        # A teacher that ignores its input and always says "the left is near": its
        # prediction on a mirrored photo, flipped back, must say "the right is near".
        # A builder that forgot to flip back would store the same ramp twice.
        def left_is_near(rgb):
            return np.tile(np.linspace(1.0, 0.0, rgb.shape[1], dtype=np.float32), (rgb.shape[0], 1))

        stack = distill.ensemble_predictions(test_photo(), left_is_near, SMALL)
        direct, mirrored = stack[0::2], stack[1::2]
        np.testing.assert_allclose(mirrored, direct[..., ::-1], atol=1e-5)

    def test_median_ignores_one_broken_resolution(self):
        rgb = test_photo()
        rng = np.random.default_rng(SEED)

        def flaky(rgb_square):
            if rgb_square.shape[0] == SMALL[2]:
                return rng.normal(size=rgb_square.shape[:2]).astype(np.float32) * 100
            return red_teacher(rgb_square)

        clean = distill.pseudo_ground_truth(rgb, red_teacher, SMALL)
        noisy = distill.pseudo_ground_truth(rgb, flaky, SMALL)
        err = np.abs(clean - noisy).max()
        self.assertLess(err, 0.1, f"seed {SEED}: two outliers out of ten moved the median by {err}")

    def test_teacher_output_of_another_size_is_resized(self):
        def half_size(rgb):
            return red_teacher(rgb)[::2, ::2]

        label = distill.pseudo_ground_truth(test_photo(), half_size, SMALL)
        expected = distill.pseudo_ground_truth(test_photo(), red_teacher, SMALL)
        self.assertLess(np.abs(label - expected).max(), 0.1)

    def test_bad_teacher_output_is_an_error(self):
        with self.assertRaisesRegex(ValueError, "2-D disparity"):
            distill.ensemble_predictions(test_photo(), lambda rgb: rgb, SMALL)

    def test_bad_photo_is_an_error(self):
        with self.assertRaisesRegex(ValueError, "H x W x 3"):
            distill.ensemble_predictions(np.zeros((8, 8), np.float32), red_teacher, SMALL)


class LabelFolder(unittest.TestCase):
    """distill.py's folder serves train_depth.py as `ampi distill`'s does: labels.tsv
    with the recipe, a line per labelled photo, resumable, and refusing a folder that is
    not its own."""

    def photos(self, root: Path) -> Path:
        from PIL import Image
        for i, name in enumerate(("a/one.jpg", "a/two.png", "b/three.jpg")):
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray((test_photo(30, 44, seed=i) * 255).astype(np.uint8)).save(root / name)
        return root

    def test_labels_resume_and_refusals(self):
        with tempfile.TemporaryDirectory() as folder:
            photos, out = self.photos(Path(folder) / "photos"), Path(folder) / "labels"
            distill.label_folder(photos, out, red_teacher, (32, 48), keep_aspect=True,
                                 teacher_name="teacher\tred\t-\t-")
            lines = (out / "labels.tsv").read_text().splitlines()
            self.assertEqual(lines[:4], ["ampi-distill\t1", "teacher\tred\t-\t-", "resolutions\t32,48\taspect kept",
                                         f"images\t{photos.resolve()}"])
            self.assertEqual(lines[4:], ["a_one.npy\ta/one.jpg", "a_two.npy\ta/two.png", "b_three.npy\tb/three.jpg"])
            images, labels = distill.read_label_folder(out)
            self.assertEqual(images, photos.resolve())
            self.assertEqual(distill.read_disparity(labels["a/two.png"]).shape, (30, 44))

            def must_not_run(rgb):
                raise AssertionError("a labelled photo was labelled again")

            distill.label_folder(photos, out, must_not_run, (32, 48), keep_aspect=True,
                                 teacher_name="teacher\tred\t-\t-")
            with self.assertRaisesRegex(SystemExit, "another teacher, resolutions or photo folder"):
                distill.label_folder(photos, out, red_teacher, (32, 64), keep_aspect=True,
                                     teacher_name="teacher\tred\t-\t-")
            (out / "labels.tsv").unlink()
            with self.assertRaisesRegex(SystemExit, "not empty and has no labels.tsv"):
                distill.label_folder(photos, out, red_teacher, (32, 48), teacher_name="teacher\tred\t-\t-")


if __name__ == "__main__":
    unittest.main()

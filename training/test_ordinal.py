"""Tests of training/ordinal_data.py: the ranking loss, WHDR, the crops' point mapping,
and reading an ordinal set."""
import itertools
import json
import random
import sys
import tempfile
import unittest
import unittest.mock
from pathlib import Path

import numpy as np
import torch
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ordinal_data  # noqa: E402
sys.path.insert(0, str(Path(__file__).resolve().parent / "ordinal"))
import pairs  # noqa: E402
import mirror_whdr  # noqa: E402


def coordinate_photo(w, h):
    """A photo whose red channel is x // 4 and green channel y // 4, to find points again."""
    y, x = np.mgrid[0:h, 0:w]
    return np.stack([x // 4, y // 4, np.zeros_like(x)], -1).astype(np.uint8)


class RankingAndWhdr(unittest.TestCase):
    def setUp(self):
        ramp = torch.arange(12, dtype=torch.float32).view(1, 12, 1).expand(1, 12, 16)  # lower = nearer
        self.disparity = ramp.clone()
        self.points = torch.tensor([[[3.0, 10.0], [5.0, 1.0]], [[8.0, 2.0], [8.0, 9.0]]])

    def test_whdr_of_right_wrong_and_tied_orders(self):
        right = torch.tensor([1.0, -1.0])
        self.assertEqual(ordinal_data.whdr_counts(self.disparity, self.points, right), (0.0, 2))
        self.assertEqual(ordinal_data.whdr_counts(self.disparity, self.points, -right), (2.0, 2))
        self.assertEqual(ordinal_data.whdr_counts(torch.ones(1, 12, 16), self.points, right), (1.0, 2))

    def test_ranking_loss_is_small_when_right_and_its_gradient_pushes_towards_the_label(self):
        signs = torch.tensor([1.0, -1.0])
        right = ordinal_data.ranking_loss(self.disparity[None], [(self.points, signs)])
        wrong = ordinal_data.ranking_loss(self.disparity[None], [(self.points, -signs)])
        self.assertLess(float(right), 0.01)
        self.assertGreater(float(wrong), 5)
        flat = torch.zeros(1, 1, 12, 16, requires_grad=True)
        ordinal_data.ranking_loss(flat, [(self.points[:1], signs[:1])]).backward()
        self.assertLess(float(flat.grad[0, 0, 10, 3]), 0)   # A (labelled nearer) pushed up
        self.assertGreater(float(flat.grad[0, 0, 1, 5]), 0)  # B pushed down

    def test_a_batch_without_pairs_costs_nothing(self):
        self.assertEqual(float(ordinal_data.ranking_loss(torch.zeros(2, 1, 4, 4), [])), 0.0)


class Mirrored(unittest.TestCase):
    """mirror_whdr.py: the mirrored run reads its disparity back in the photo's own frame."""

    class Ramp:
        """A stand-in network whose disparity grows along x (or y): [N, 1, H, W] as the last
        of its outputs, like depth_model.DepthNet."""
        multiple = 32

        def __init__(self, axis):
            self.axis = axis

        def __call__(self, x):
            n, _, h, w = x.shape
            ramp = torch.arange(w if self.axis == "x" else h, dtype=torch.float32)
            ramp = ramp.view(1, 1, 1, w) if self.axis == "x" else ramp.view(1, 1, h, 1)
            return [ramp.expand(n, 1, h, w)]

    def setUp(self):
        rgb = np.random.default_rng(3).integers(0, 256, (90, 120, 3), dtype=np.uint8)
        # A (right, low) nearer than B (left, high): right for both ramps as the photo is.
        points = np.array([[[100.0, 80.0], [20.0, 10.0]]], np.float32)
        self.photos = [ordinal_data.OrdinalPhoto(rgb, points, np.array([1.0], np.float32))]

    def test_a_left_right_ramp_is_wrong_only_mirrored(self):
        self.assertEqual(mirror_whdr.whdr_both_ways(self.Ramp("x"), self.photos, 64), (0.0, 1.0, 1))

    def test_a_top_bottom_ramp_is_right_both_ways(self):
        self.assertEqual(mirror_whdr.whdr_both_ways(self.Ramp("y"), self.photos, 64), (0.0, 0.0, 1))


class Crops(unittest.TestCase):
    def test_points_follow_the_crop_resize_and_flip(self):
        rgb = coordinate_photo(320, 240)
        points = np.array([[[17.0, 33.0], [300.0, 200.0]], [[160.0, 120.0], [40.0, 220.0]]], np.float32)
        teacher = np.mgrid[0:240, 0:320][1].astype(np.float32) / 320  # a label rising to the right
        photo = ordinal_data.OrdinalPhoto(rgb, points, np.array([1.0, -1.0], np.float32), teacher)
        for seed, share in itertools.product(range(20), (ordinal_data.CROP_SHARE, ordinal_data.WIDE_CROP_SHARE)):
            image, mapped, signs, label = ordinal_data.training_sample(photo, (64, 48), random.Random(seed), share)
            self.assertEqual(tuple(image.shape), (3, 48, 64))
            self.assertEqual(tuple(label.shape), (1, 48, 64))
            for pair, sign in zip(mapped, signs):
                original = points[0] if sign > 0 else points[1]
                for (x, y), (ox, oy) in zip(pair.tolist(), original):
                    pixel = image[:, min(47, round(y)), min(63, round(x))] * 255
                    # one 64-px-wide cell is at most 8 px of the photo: within 3 of x // 4
                    self.assertLess(abs(float(pixel[0]) - ox / 4), 3.5)
                    self.assertLess(abs(float(pixel[1]) - oy / 4), 3.5)
                    # the label is cropped, resized and flipped with the photo
                    self.assertLess(abs(float(label[0, min(47, round(y)), min(63, round(x))]) - ox / 320), 0.03)

    def test_no_teacher_no_label(self):
        photo = ordinal_data.OrdinalPhoto(coordinate_photo(64, 48), np.zeros((0, 2, 2), np.float32),
                                          np.zeros(0, np.float32))
        self.assertIsNone(ordinal_data.training_sample(photo, (32, 32), random.Random(0))[3])


class Reading(unittest.TestCase):
    def test_load_split_keeps_ordered_pairs_and_checks_the_size(self):
        with tempfile.TemporaryDirectory() as folder:
            root = Path(folder)
            Image.fromarray(coordinate_photo(100, 80)).save(root / "a.png")
            pairs = [{"a": [10, 70], "b": [50, 5], "label": "A"}, {"a": [1, 1], "b": [2, 2], "label": "="}]
            entry = {"photo": "a.png", "width": 100, "height": 80, "split": "val", "pairs": pairs}
            (root / "set.json").write_text(json.dumps({"photos": [entry]}))
            [photo] = ordinal_data.load_split("val", root, root / "set.json")
            self.assertEqual(photo.points.shape, (1, 2, 2))
            self.assertEqual(photo.signs.tolist(), [1.0])
            with self.assertRaisesRegex(RuntimeError, "no labelled photos in split train"):
                ordinal_data.load_split("train", root, root / "set.json")
            entry["width"] = 120
            (root / "set.json").write_text(json.dumps({"photos": [entry]}))
            with self.assertRaisesRegex(RuntimeError, "a.png: is \\(100, 80\\), labelled at 120x80"):
                ordinal_data.load_split("val", root, root / "set.json")
            archive = dict(entry, photo="archive/b.jpg")
            (root / "set.json").write_text(json.dumps({"photos": [archive]}))
            with self.assertRaisesRegex(RuntimeError, "archive/b.jpg is not under .*AMPI_PHOTO_ROOT"):
                ordinal_data.load_split("val", root, root / "set.json")

    def test_only_training_photos_are_left_to_training(self):
        """validation_photos (kept out of every other training source) holds the val, test
        and holdout photos, labelled or not."""
        with tempfile.TemporaryDirectory() as folder:
            root = Path(folder)
            entries = [{"photo": f"{split}.png", "width": 4, "height": 4, "split": split, "pairs": []}
                       for split in ("train", "val", "test", "holdout")]
            (root / "set.json").write_text(json.dumps({"photos": entries}))
            self.assertEqual(ordinal_data.validation_photos(root, root / "set.json"),
                             {(root / f"{split}.png").resolve() for split in ("val", "test", "holdout")})

    def test_teacher_labels_are_read_at_the_photos_size(self):
        with tempfile.TemporaryDirectory() as folder:
            root = Path(folder)
            (root / "photos").mkdir()
            Image.fromarray(coordinate_photo(100, 80)).save(root / "photos" / "a.png")
            pairs = [{"a": [10, 70], "b": [50, 5], "label": "B"}]
            entry = {"photo": "a.png", "width": 100, "height": 80, "split": "train", "pairs": pairs}
            (root / "set.json").write_text(json.dumps({"photos": [entry]}))
            labels = root / "labels"
            labels.mkdir()
            ramp = (np.mgrid[0:40, 0:50][0] * 1000).astype(np.uint16)  # half size, rising downwards
            Image.fromarray(ramp).save(labels / "a.png")
            header = f"ampi-distill\t1\nteacher\tt.ampw\tlite\tx\nresolutions\t32\nimages\t{root / 'photos'}\n"
            (labels / "labels.tsv").write_text(header + "a.png\ta.png\n")
            [photo] = ordinal_data.load_split("train", root / "photos", root / "set.json", labels)
            self.assertEqual(photo.teacher.shape, (80, 100))
            self.assertLess(float(photo.teacher[0, 0]), float(photo.teacher[79, 0]))
            self.assertAlmostEqual(float(photo.teacher.max()), 39000 / 65535, delta=0.02)
            # the label puts A (lower in the photo) nearer; the pair says B: all wrong
            self.assertEqual(ordinal_data.labels_whdr(labels, "train", root / "photos", root / "set.json"), (1.0, 1))
            (labels / "labels.tsv").write_text(header)
            with self.assertRaisesRegex(ValueError, "no label for a.png"):
                ordinal_data.load_split("train", root / "photos", root / "set.json", labels)


class Labelling(unittest.TestCase):
    def test_pairs_are_drawn_inside_the_photo_the_same_way_every_time(self):
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "p.png"
            Image.fromarray(coordinate_photo(300, 200)).save(path)
            with unittest.mock.patch.object(pairs.photo_folder, "ordinal_split", return_value="train"):
                first, again = pairs.sample_photo(path, "x/p.png"), pairs.sample_photo(path, "x/p.png")
        self.assertEqual(first, again)
        one_round = ["random"] * pairs.RANDOM_PAIRS + ["edge"] * pairs.EDGE_PAIRS
        self.assertEqual([p["kind"] for p in first["pairs"]], one_round * pairs.ROUNDS)
        self.assertEqual([p["id"] for p in first["pairs"]], list(range(1, pairs.ROUNDS * len(one_round) + 1)))
        self.assertEqual([pairs.round_of(p["id"]) for p in first["pairs"]],
                         [r for r in range(1, pairs.ROUNDS + 1) for _ in one_round])
        for pair in first["pairs"]:
            for x, y in (pair["a"], pair["b"]):
                self.assertTrue(0 <= x < 300 and 0 <= y < 200, pair)

    def test_the_test_rounds_of_a_validation_photo_are_an_entry_of_their_own(self):
        def pair(i):
            return {"id": i, "label": "A"}
        first, test_round = [pair(1), pair(8)], [pair(7 * (r - 1) + 2) for r in pairs.TEST_ROUNDS]
        self.assertEqual(pairs.split_parts("val", first + test_round), [("val", first), ("test", test_round)])
        self.assertEqual(pairs.split_parts("val", first), [("val", first)])
        self.assertEqual(pairs.split_parts("val", test_round), [("test", test_round)])
        self.assertEqual(pairs.split_parts("train", first + test_round), [("train", first + test_round)])
        self.assertEqual(pairs.split_parts("train", []), [])

    def test_a_gzip_pair_file_reads_back_and_is_the_same_bytes_every_time(self):
        photos = [{"photo": "kodak24/a.png", "width": 4, "height": 3, "split": "train",
                   "pairs": [{"id": 1, "kind": "random", "a": [0.5, 1.0], "b": [3.0, 2.5]}]}]
        with tempfile.TemporaryDirectory() as tmp:
            first, second = Path(tmp) / "one.json.gz", Path(tmp) / "two.json.gz"
            pairs.write_set(first, {"seed": 1}, photos)
            pairs.write_set(second, {"seed": 1}, photos)
            self.assertEqual(pairs.read_pairs(first), photos)
            self.assertEqual(first.read_bytes(), second.read_bytes())

    def test_a_subset_keeps_the_named_photos_and_rounds(self):
        def entry(name, ids):  # pairs 6 and 7 of a round are its edge pairs
            return {"photo": name, "pairs": [{"id": i, "label": "A", "kind": "edge" if (i - 1) % 7 >= 5 else "random"}
                                             for i in ids]}
        photos = [entry("archive/mate_a.jpg", [1, 8, 15]), entry("archive/opencv_b.jpg", [2]),
                  entry("kodak24/c.png", [3, 9, 13]), entry("archive/plasma_d.jpg", [16])]
        self.assertEqual(pairs.subset(photos, ["archive/mate_", "archive/plasma_"], (1, 2)),
                         [entry("archive/mate_a.jpg", [1, 8])])
        self.assertEqual(pairs.subset(photos, [], (2, 2)),
                         [entry("archive/mate_a.jpg", [8]), entry("kodak24/c.png", [9, 13])])
        self.assertEqual(pairs.subset(photos, [], (1, 3), "edge"), [entry("kodak24/c.png", [13])])
        self.assertEqual(pairs.subset(photos, ["kodak24/"], (1, 3), "random"), [entry("kodak24/c.png", [3, 9])])

    def test_an_order_is_kept_only_when_every_labeller_gave_it(self):
        self.assertEqual(pairs.consensus(["A"]), "A")
        self.assertEqual(pairs.consensus(["B", "B"]), "B")
        self.assertEqual(pairs.consensus(["A", "="]), "=")
        self.assertEqual(pairs.consensus(["A", "B"]), "=")
        votes = {("p", 1): ["A", "A"], ("p", 2): ["A", "B"], ("p", 3): ["=", "B"], ("p", 4): ["A"]}
        self.assertEqual(pairs.agreement(votes), (3, 1, 1))

    def test_label_files_are_checked_line_by_line(self):
        with tempfile.TemporaryDirectory() as folder:
            (Path(folder) / "one.tsv").write_text("p.jpg\t1\tA\np.jpg\t2\t=\n")
            (Path(folder) / "two.tsv").write_text("p.jpg\t1\tB\n")
            self.assertEqual(pairs.read_labels(folder), {("p.jpg", 1): ["A", "B"], ("p.jpg", 2): ["="]})
            (Path(folder) / "two.tsv").write_text("p.jpg\t1\tnearer\n")
            with self.assertRaisesRegex(SystemExit, "two.tsv:1: expected"):
                pairs.read_labels(folder)
            (Path(folder) / "two.tsv").write_text("p.jpg\t1\tA\np.jpg\t1\tB\n")
            with self.assertRaisesRegex(SystemExit, "two.tsv:2: .* labelled twice in one file"):
                pairs.read_labels(folder)


if __name__ == "__main__":
    unittest.main()

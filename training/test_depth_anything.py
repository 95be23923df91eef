"""Tests of the Depth Anything V2 twin and its importer (run by ctest as
`depth_anything_python`: `/usr/bin/python3 -m unittest training/test_depth_anything.py`).

Tiny configurations only, except one build of the real vits to check its key names and
size; the comparison with the official code is check_depth_anything.py (needs the
official repository, so not part of ctest)."""
import io
import sys
import tempfile
import unittest
from contextlib import redirect_stderr
from pathlib import Path
from unittest import mock

import numpy as np
import torch

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "weights_format"))
import depth_anything as dav2  # noqa: E402
import import_depth_anything as importer  # noqa: E402
import make_dav2_fixtures  # noqa: E402
from ampw import read_ampw  # noqa: E402

SEED = 5
# A tiny "variant" for the importer's recognition (by embed dim) in these tests.
TINY_32 = dav2.tiny(embed_dim=32, depth=4, heads=2, layers=(0, 1, 2, 3), out_channels=(8, 16, 24, 32))


def tiny_model(cfg=dav2.TINY, seed=SEED):
    return dav2.randomise_(dav2.build(cfg), seed)


def relative_error(a: torch.Tensor, b: torch.Tensor) -> float:
    return float((a - b).abs().max()) / max(float(a.max() - a.min()), 1e-30)


class Twin(unittest.TestCase):
    def test_output_shape_follows_the_input(self):
        model = tiny_model()
        for h, w in ((56, 56), (70, 98), (42, 126)):
            with torch.no_grad():
                self.assertEqual(tuple(model(torch.randn(2, 3, h, w)).shape), (2, h, w))

    def test_pyramid_scales_are_4_2_1_and_half_the_grid(self):
        model = tiny_model()
        with torch.no_grad():
            tokens = model.pretrained.intermediate(torch.randn(1, 3, 70, 98))
            maps = model.depth_head.pyramid(tokens, 5, 7)
        self.assertEqual([tuple(m.shape[-2:]) for m in maps], [(20, 28), (10, 14), (5, 7), (3, 4)])
        self.assertTrue(all(m.shape[1] == dav2.TINY.features for m in maps))

    def test_deterministic_for_a_seed(self):
        x = torch.randn(1, 3, 70, 98, generator=torch.Generator().manual_seed(SEED))
        with torch.no_grad():
            a, b = tiny_model()(x), tiny_model()(x)
            c = tiny_model(seed=SEED + 1)(x)
        self.assertTrue(torch.equal(a, b))
        self.assertFalse(torch.equal(a, c))
        self.assertGreater(float((a > 0).float().mean()), 0.5, "random weights should not zero most pixels")

    def test_rejects_sizes_off_the_patch_grid(self):
        with self.assertRaisesRegex(ValueError, "multiple of the patch size 14"):
            tiny_model()(torch.randn(1, 3, 56, 60))

    def test_vits_has_the_official_keys_and_size(self):
        state = dav2.build("vits").state_dict()
        self.assertEqual(len(state), 239)
        self.assertEqual(sum(t.numel() for t in state.values()), 24_785_089)  # the official model's count
        for key, shape in (("pretrained.pos_embed", (1, 1370, 384)), ("pretrained.blocks.11.ls2.gamma", (384,)),
                           ("pretrained.mask_token", (1, 384)), ("depth_head.resize_layers.0.weight", (48, 48, 4, 4)),
                           ("depth_head.resize_layers.3.weight", (384, 384, 3, 3)),
                           ("depth_head.scratch.refinenet4.resConfUnit1.conv1.weight", (64, 64, 3, 3)),
                           ("depth_head.scratch.output_conv2.2.bias", (1,))):
            self.assertEqual(tuple(state[key].shape), shape, key)


class PositionEmbedding(unittest.TestCase):
    def test_unchanged_on_the_pretraining_grid(self):
        pos = torch.randn(1, 17, 8)
        self.assertIs(dav2.interpolate_pos_embed(pos, 4, 4, 0.1), pos)

    def test_bicubic_with_the_offset_scale_factor(self):
        """The explicit formula (cubic_resize_matrix: src = (i + 0.5) * G / (n + 0.1) - 0.5)
        equals what the twin computes; the plain size ratio G / n does not."""
        g = torch.Generator().manual_seed(SEED)
        pos = torch.randn(1, 17, 8, generator=g)
        grid = pos[0, 1:].reshape(4, 4, 8).double().numpy()
        for rows, cols in ((5, 7), (3, 9), (4, 6), (8, 8)):
            got = dav2.interpolate_pos_embed(pos, rows, cols, 0.1)
            self.assertTrue(torch.equal(got[0, 0], pos[0, 0]))
            got = got[0, 1:].reshape(rows, cols, 8).double().numpy()

            def resized(offset):
                r = dav2.cubic_resize_matrix(rows, 4, 4 / (rows + offset))
                c = dav2.cubic_resize_matrix(cols, 4, 4 / (cols + offset))
                return np.einsum("ia,abc,jb->ijc", r, grid, c)

            self.assertLess(np.abs(resized(0.1) - got).max(), 1e-5, (rows, cols))
            self.assertGreater(np.abs(resized(0.0) - got).max(), 1e-3, (rows, cols))


class Preprocessing(unittest.TestCase):
    def test_working_shape_is_the_reference_lower_bound(self):
        self.assertEqual(dav2.working_shape(518, 518), (518, 518))
        self.assertEqual(dav2.working_shape(480, 640), (518, 686))
        self.assertEqual(dav2.working_shape(333, 500), (518, 784))
        self.assertEqual(dav2.working_shape(4000, 3000), (686, 518))
        # 525 / 14 = 37.5 and 539 / 14 = 38.5 both round to 38 (halves to even, as np.round)
        self.assertEqual(dav2.working_shape(1036, 1050), (518, 532))
        self.assertEqual(dav2.working_shape(1036, 1078), (518, 532))
        # a size that is no multiple: the fitted side is raised to the next multiple
        self.assertEqual(dav2.working_shape(600, 800, size=520), (532, 700))

    def test_preprocess_resizes_and_normalises(self):
        image = np.zeros((30, 40, 3), np.uint8)
        image[...] = (255, 128, 0)
        x = dav2.preprocess(image, size=56)
        self.assertEqual(tuple(x.shape), (1, 3, 56, 70))
        expected = (np.array([255, 128, 0]) / 255.0 - np.array(dav2.IMAGENET_MEAN)) / np.array(dav2.IMAGENET_STD)
        self.assertLess(np.abs(x[0].permute(1, 2, 0).numpy() - expected).max(), 1e-5)

    def test_infer_returns_the_photo_size(self):
        photo = np.random.default_rng(SEED).random((45, 61, 3)).astype(np.float32)
        out = dav2.infer(tiny_model(), photo, size=56)
        self.assertEqual(out.shape, (45, 61))
        self.assertGreaterEqual(float(out.min()), 0.0)


class LayerScaleFolding(unittest.TestCase):
    def test_folded_weights_compute_the_same_function(self):
        model = tiny_model()
        state = model.state_dict()
        folded = dav2.build(dav2.TINY)
        folded.load_state_dict(dav2.fold_layer_scale(state))
        self.assertTrue(all(torch.equal(v, torch.ones_like(v)) for k, v in folded.state_dict().items()
                            if k.endswith("gamma")))
        self.assertFalse(torch.equal(folded.state_dict()["pretrained.blocks.0.mlp.fc2.weight"],
                                     state["pretrained.blocks.0.mlp.fc2.weight"]))
        x = torch.randn(1, 3, 70, 98, generator=torch.Generator().manual_seed(SEED))
        with torch.no_grad():
            self.assertLess(relative_error(model(x), folded(x)), 1e-5)


class Importer(unittest.TestCase):
    """The importer recognises only the real widths; TINY_32 joins them while a test runs."""

    def setUp(self):
        patch = mock.patch.dict(dav2.VARIANTS, {"tiny32": TINY_32})
        patch.start()
        self.addCleanup(patch.stop)
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)
        self.model = tiny_model(TINY_32)
        self.pth = self.path("dav2_tiny32.pth")
        torch.save(self.model.state_dict(), self.pth)

    def path(self, name: str) -> str:
        return str(Path(self.tmp.name) / name)

    def test_round_trip_through_pth_and_ampw(self):
        out = self.path("tiny32.ampw")
        meta = importer.convert(self.pth, out)
        self.assertEqual(meta["depth.variant"], "tiny32")
        read_meta, tensors = read_ampw(out)
        self.assertEqual(read_meta["arch"], "ampi.depth.dav2-vit-dpt")
        self.assertEqual(list(read_meta["dav2.layers"]), [0, 1, 2, 3])
        self.assertEqual(read_meta["dav2.embed_dim"], 32)
        self.assertEqual(len(read_meta["source.sha256"]), 64)
        self.assertFalse([k for k in tensors if "gamma" in k or "mask_token" in k or "refinenet4.resConfUnit1" in k])
        self.assertEqual(tensors["pretrained.patch_embed.proj.weight"].shape, (32, 14, 14, 3))
        self.assertEqual(tensors["depth_head.resize_layers.0.weight"].shape, (4, 4, 8, 8))
        self.assertEqual(read_meta["depth.parameters"], sum(a.size for a in tensors.values()))
        rebuilt = importer.import_ampw(out)
        x = torch.randn(1, 3, 70, 98, generator=torch.Generator().manual_seed(SEED))
        with torch.no_grad():
            self.assertLess(relative_error(self.model(x), rebuilt(x)), 1e-5)

    def test_transposed_convolution_layout(self):
        """[kh][kw][out][in]: entry (i, j, o, c) is PyTorch's weight[c, o, i, j]."""
        w = self.model.state_dict()["depth_head.resize_layers.1.weight"]
        a = importer.to_file_layout("depth_head.resize_layers.1.weight", w)
        self.assertEqual(float(a[1, 0, 3, 5]), float(w[5, 3, 1, 0]))
        back = importer.from_file_layout("depth_head.resize_layers.1.weight", a, w)
        self.assertTrue(torch.equal(back, w))

    def assert_refused(self, path: str, pattern: str):
        out = self.path("out.ampw")
        stderr = io.StringIO()
        with redirect_stderr(stderr):
            code = importer.main([path, out])
        message = stderr.getvalue()
        self.assertEqual(code, 1)
        self.assertEqual(message.count("\n"), 1, message)
        self.assertTrue(message.startswith(path + ": "), message)
        self.assertRegex(message, pattern)
        self.assertFalse(Path(out).exists())
        self.assertEqual([p.name for p in Path(self.tmp.name).iterdir() if p.name.startswith("out")], [])

    def saved(self, name: str, obj) -> str:
        path = self.path(name)
        torch.save(obj, path)
        return path

    def test_missing_and_empty_files(self):
        self.assert_refused(self.path("absent.pth"), "cannot read: No such file")
        Path(self.path("empty.pth")).write_bytes(b"")
        self.assert_refused(self.path("empty.pth"), "empty file")

    def test_truncated_and_foreign_files(self):
        data = Path(self.pth).read_bytes()
        Path(self.path("cut.pth")).write_bytes(data[:len(data) // 2])
        self.assert_refused(self.path("cut.pth"), "not a readable PyTorch checkpoint")
        Path(self.path("text.pth")).write_text("hello\n")
        self.assert_refused(self.path("text.pth"), "not a readable PyTorch checkpoint")
        self.assert_refused(self.saved("list.pth", [torch.zeros(2)]), "holds a list, not a state dict")
        foreign = {"model": {"enc1.0.conv.weight": torch.zeros(16, 12, 3, 3)}, "step": 3}
        self.assert_refused(self.saved("foreign.pth", foreign), "not a Depth Anything V2 checkpoint")

    def test_wrong_sizes_and_contents(self):
        state = self.model.state_dict()
        giant = {importer.PATCH_KEY: torch.zeros(1536, 3, 14, 14)}
        self.assert_refused(self.saved("giant.pth", giant), "embed dim 1536 .ViT-G, not supported.")
        fewer = {k: v for k, v in state.items() if not k.startswith("pretrained.blocks.3.")}
        self.assert_refused(self.saved("fewer.pth", fewer), "is missing 14 tensor.*pretrained.blocks.3.norm1")
        extra = dict(state, **{"depth_head.readout_projects.0.0.weight": torch.zeros(32, 64)})
        self.assert_refused(self.saved("extra.pth", extra), "has unexpected 1 tensor.*readout_projects")
        reshaped = dict(state, **{"depth_head.scratch.layer1_rn.weight": torch.zeros(8, 8, 1, 1)})
        self.assert_refused(self.saved("reshaped.pth", reshaped), r"layer1_rn.weight' has shape \(8, 8, 1, 1\)")
        broken = dict(state, **{"pretrained.norm.bias": torch.full((32,), float("nan"))})
        self.assert_refused(self.saved("nan.pth", broken), "'pretrained.norm.bias' holds non-finite values")
        self.assert_refused(self.saved("depth_anything_v2_metric_hypersim_vits.pth", state), "metric-depth")

    def test_unwritable_output(self):
        stderr = io.StringIO()
        out = self.path("no/such/dir/out.ampw")
        with redirect_stderr(stderr):
            self.assertEqual(importer.main([self.pth, out]), 1)
        self.assertRegex(stderr.getvalue(), "^" + out + ": cannot write: ")


class Fixtures(unittest.TestCase):
    def test_committed_fixtures_are_what_the_script_writes(self):
        committed = make_dav2_fixtures.FIXTURES
        with tempfile.TemporaryDirectory() as tmp, redirect_stderr(io.StringIO()):
            with mock.patch("sys.stdout", io.StringIO()):
                make_dav2_fixtures.main(["--out", tmp])
            for path in sorted(Path(tmp).iterdir()):
                mine = committed / path.name
                self.assertTrue(mine.exists(), f"{mine} missing: run training/make_dav2_fixtures.py")
                if path.suffix == ".npy":
                    np.testing.assert_allclose(np.load(mine), np.load(path), rtol=0, atol=1e-5, err_msg=path.name)
                else:
                    meta_a, tensors_a = read_ampw(str(mine))
                    meta_b, tensors_b = read_ampw(str(path))
                    self.assertEqual(sorted(tensors_a), sorted(tensors_b))
                    for k in tensors_a:
                        np.testing.assert_array_equal(tensors_a[k], tensors_b[k], err_msg=k)
        self.assertLess((committed / "dav2_tiny.ampw").stat().st_size, 200_000)


if __name__ == "__main__":
    unittest.main()

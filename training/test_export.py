"""Tests of the exporter (run by ctest: `/usr/bin/python3 -m unittest training/test_export.py`):
BatchNorm folding and the OHWI layout survive a round trip through the weight file, the
metadata describes the graph, and the two sizes match the paper's."""
import sys
import tempfile
import unittest
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import depth_model  # noqa: E402
import export_depth  # noqa: E402

SEED = 7


def randomised(model: depth_model.DepthNet, seed: int) -> depth_model.DepthNet:
    """Non-trivial BatchNorm statistics, so a wrong fold shows."""
    g = torch.Generator().manual_seed(seed)
    for m in model.modules():
        if isinstance(m, torch.nn.BatchNorm2d):
            m.weight.data = torch.rand(m.num_features, generator=g) + 0.5
            m.bias.data = torch.randn(m.num_features, generator=g) * 0.1
            m.running_mean = torch.randn(m.num_features, generator=g) * 0.1
            m.running_var = torch.rand(m.num_features, generator=g) + 0.5
    return model.eval()


class Export(unittest.TestCase):
    def test_round_trip_reproduces_every_output(self):
        torch.manual_seed(SEED)
        model = randomised(depth_model.build("lite"), SEED)
        rgb = torch.rand(1, 3, 64, 96, generator=torch.Generator().manual_seed(SEED))
        with tempfile.TemporaryDirectory() as tmp:
            path = str(Path(tmp) / "lite.ampw")
            meta = export_depth.export(model, path, {"steps": 0})
            reloaded = export_depth.import_ampw(path)
        self.assertEqual(meta["depth.parameters"], depth_model.folded_parameter_count(model))
        with torch.no_grad():
            for i, (a, b) in enumerate(zip(model(rgb), reloaded(rgb))):
                scale = float(a.abs().max())
                err = float((a - b).abs().max())
                self.assertLess(err, 1e-5 * max(scale, 1.0), f"seed {SEED}, output {i}: error {err}")

    def test_unfolded_batchnorm_keeps_the_function_and_normalises_its_input(self):
        torch.manual_seed(SEED)
        model = randomised(depth_model.build("lite"), SEED)
        g = torch.Generator().manual_seed(SEED)
        batches = [torch.rand(2, 3, 64, 96, generator=g) for _ in range(3)]
        rgb = torch.rand(1, 3, 64, 96, generator=g)
        with tempfile.TemporaryDirectory() as tmp:
            path = str(Path(tmp) / "lite.ampw")
            export_depth.export(model, path, {"steps": 0})
            unfolded = export_depth.unfold_batchnorm(export_depth.import_ampw(path), batches)
        with torch.no_grad():
            for i, (a, b) in enumerate(zip(model(rgb), unfolded.eval()(rgb))):
                err = float((a - b).abs().max())
                self.assertLess(err, 1e-4 * max(float(a.abs().max()), 1.0), f"seed {SEED}, output {i}: error {err}")
        first = unfolded.enc[0][0].bn
        self.assertGreater(float((first.running_var - (1 - first.eps)).abs().max()), 1e-3)  # real statistics now

    def test_metadata_describes_the_graph(self):
        model = depth_model.build("lite")
        with tempfile.TemporaryDirectory() as tmp:
            meta = export_depth.export(model, str(Path(tmp) / "x.ampw"), {"steps": 3})
        self.assertEqual(meta["arch"], export_depth.ARCH_NAME)
        self.assertEqual(meta["depth.levels"], 5)
        self.assertEqual(meta["depth.multiple"], 32)
        self.assertEqual(meta["train.steps"], 3)
        self.assertEqual(len(meta["train.commit"]), 40)
        first = meta["depth.encoder.1"][:export_depth.FIELDS_PER_BLOCK]
        self.assertEqual(first, [0, 16, 0, 3, 0, 2])  # conv, 16 out, 3x3, hard-swish

    def test_averaged_exports_the_weight_average_and_needs_one(self):
        raw, average = (randomised(depth_model.build("lite"), seed) for seed in (SEED, SEED + 1))
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "checkpoint.pt"
            torch.save({"model_name": "lite", "model": raw.state_dict(), "ema": average.state_dict(), "step": 5}, path)
            for averaged, expected in ((False, raw), (True, average)):
                model, _ckpt = export_depth.load_checkpoint(str(path), averaged)
                self.assertTrue(torch.equal(model.state_dict()["enc.0.0.bn.running_var"],
                                            expected.state_dict()["enc.0.0.bn.running_var"]))
            torch.save({"model_name": "lite", "model": raw.state_dict(), "step": 5}, path)
            with self.assertRaisesRegex(SystemExit, "no weight average"):
                export_depth.load_checkpoint(str(path), averaged=True)

    def test_sizes_match_the_paper(self):
        for name, paper_mb in (("lite", 10.6), ("heavy", 25.2)):
            mb = depth_model.folded_parameter_count(depth_model.build(name)) * 4 / 1e6
            self.assertLess(abs(mb - paper_mb) / paper_mb, 0.15, f"{name}: {mb:.2f} MB")


if __name__ == "__main__":
    unittest.main()

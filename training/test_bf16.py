"""train_depth.py --bf16: bfloat16 autocast for the training forward pass. The body's
convolutions run in bf16 while the heads, and so the outputs and every loss, stay fp32
(depth_model.DepthNet.head); one step's gradient then points where fp32's does, and a
tiny run trains under it and says so in its log."""
import math
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import torch

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import bf16_agreement  # noqa: E402
import depth_model  # noqa: E402
import train_depth  # noqa: E402


def smooth_scene(seed: int, n: int = 2, side: int = 64):
    """Photos and disparities with structure at the network's scales: random values on a
    grid of 8-pixel cells, enlarged bilinearly, so the loss on the disparity's gradients
    has slopes to match."""
    g = torch.Generator().manual_seed(seed)
    cells = torch.rand(n, 4, side // 8, side // 8, generator=g)
    field = torch.nn.functional.interpolate(cells, size=(side, side), mode="bilinear", align_corners=False)
    return field[:, :3].contiguous(memory_format=torch.channels_last), field[:, 3:] * 5 + 0.5


class Bf16Test(unittest.TestCase):
    def setUp(self):
        torch.manual_seed(0)
        self.model = depth_model.build("lite").to(memory_format=torch.channels_last)

    def test_the_outputs_stay_fp32_and_near_fp32s(self):
        rgb, _ = smooth_scene(1)
        self.model.eval()
        with torch.no_grad():
            exact = self.model(rgb)
            with torch.autocast("cpu", dtype=torch.bfloat16):
                fast = self.model(rgb)
        for e, f in zip(exact, fast):
            self.assertEqual(f.dtype, torch.float32)
            error = float((f - e).pow(2).mean().sqrt() / e.std())
            self.assertGreater(error, 0.0, "autocast changed nothing: the body did not run in bf16")
            self.assertLess(error, 0.05)

    def test_one_step_s_gradient_points_where_fp32_s_does(self):
        rgb, disp = smooth_scene(2)
        scores = bf16_agreement.agreement(self.model, (rgb, disp, None, [], None),
                                          train_depth.parse_args(["--run", "unused"]))
        # 0.89 here: at random initialisation the first layers' gradients are sums that
        # largely cancel, so bf16's rounding shows most; on the long heavy run's weights
        # and real batches 0.984-0.993 (bf16_agreement.py, training/DEPTH.md)
        self.assertGreater(scores["cosine"], 0.8)
        self.assertAlmostEqual(scores["norm ratio"], 1.0, delta=0.05)

    def test_a_tiny_run_trains_under_bf16(self):
        with tempfile.TemporaryDirectory() as folder:
            run = Path(folder) / "run"
            done = subprocess.run(
                [sys.executable, str(HERE / "train_depth.py"), "--model", "lite", "--run", str(run), "--data", "scenes",
                 "--size", "64x64", "--batch", "1", "--steps", "3", "--workers", "0", "--log-every", "1",
                 "--val-every", "3", "--val-count", "1", "--bf16"],
                capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            log = (run / "train.log").read_text()
            self.assertIn("bf16 autocast", log)
            losses = [float(line.split(" loss ")[1].split()[0]) for line in log.splitlines() if " loss " in line]
            self.assertEqual(len(losses), 4)  # three steps and the validation
            self.assertTrue(all(math.isfinite(v) for v in losses))


if __name__ == "__main__":
    unittest.main()

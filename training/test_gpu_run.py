"""The GPU round trip of training/gpu_run.py, at a tiny size on the CPU: pack a photo
folder, an ordinal set and a run into a carry folder, run the device command there (with
--device cpu), unpack what it wrote to $OUT, and do it again: the second run resumes."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np
import torch
from PIL import Image

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
PYTHON = sys.executable


def make_photos(root: Path):
    """Ten small photos in one folder (the fifth and tenth are ordinal validation) and an
    ordinal set with one ordered pair on each."""
    rng = np.random.default_rng(3)
    entries = []
    for i in range(10):
        name = f"p{i}.jpg"
        (root / "photos" / "set").mkdir(parents=True, exist_ok=True)
        Image.fromarray(rng.integers(0, 255, (300, 900, 3), dtype=np.uint8)).save(root / "photos" / "set" / name)
        entries.append({"photo": f"set/{name}", "width": 900, "height": 300,
                        "split": "val" if i % 5 == 4 else "train",
                        "pairs": [{"a": [10.0, 290.0], "b": [899.0, 0.0], "label": "A"}]})
    (root / "ordinal.json").write_text(json.dumps({"photos": entries}))


class RoundTrip(unittest.TestCase):
    def run_tool(self, *args, env=None):
        result = subprocess.run([PYTHON, str(HERE / "gpu_run.py"), *args], cwd=ROOT, env=env,
                                capture_output=True, text=True)
        self.assertEqual(result.returncode, 0, result.stderr)
        return result.stdout

    def test_pack_train_unpack_twice(self):
        with tempfile.TemporaryDirectory() as folder:
            tmp = Path(folder)
            make_photos(tmp)
            env = dict(os.environ, AMPI_PHOTO_ROOT=str(tmp / "photos"))
            carry, out = tmp / "carry", tmp / "out"
            runs = {"lite": tmp / "lite", "heavy": tmp / "heavy"}
            run_args = [arg for model, run in runs.items() for arg in ("--run", f"{model}:{run}")]
            for round_trip in range(2):
                printed = self.run_tool("pack", *run_args, "--carry", str(carry), "--ordinal",
                                        str(tmp / "ordinal.json"), "--device", "cpu", "--python", PYTHON, "--size", "64x64",
                                        "--batch", "2", "--ordinal-batch", "2", "--minutes", "0.05",
                                        "--threads", "1", "--workers", "2", "--scene-reuse", "2", "--val-count", "2", env=env)
                packed = json.loads((carry / "ordinal.json").read_text())["photos"][0]
                self.assertEqual((packed["width"], packed["height"]), (384, 128))   # scaled to 384 px
                with Image.open(carry / "photos" / "set" / "p0.jpg") as photo:
                    self.assertEqual(photo.size, (384, 128))
                self.assertLess(packed["pairs"][0]["b"][0], 384)
                command = printed.strip().splitlines()[-1]
                shutil.rmtree(out, ignore_errors=True)
                out.mkdir()
                done = subprocess.run(["bash", "-c", command], cwd=ROOT, env=dict(env, OUT=str(out)),
                                      capture_output=True, text=True)
                self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
                self.run_tool("unpack", str(out), *run_args)
                for model, run in runs.items():
                    for name in ("checkpoint.pt", "best.pt", "train.log"):
                        self.assertTrue((run / name).exists(), f"{model} {name}")
                    back = torch.load(out / model / "checkpoint.pt")
                    self.assertNotIn("optimiser", back)   # slim: under the 16 MiB a returned file may have
                    self.assertIn("lr", back)
                    self.assertEqual(next(iter(back["model"].values())).dtype, torch.float16)
                    self.assertNotIn("ema", back)   # --ema 0.999: the average crosses as the weights
            for model, run in runs.items():
                log = (run / "train.log").read_text()
                self.assertIn(f"initialised {model} from weights/depth_{model}.ampw", log)
                self.assertIn("(slim: Adam restarts)", log)
                self.assertIn("weights averaged (decay 0.999)", log)
                self.assertEqual(log.count("stopped after 0.05 minutes"), 2)
                self.assertIn("ordinal_whdr", log)

    def test_unpack_without_files_leaves_the_run_alone(self):
        with tempfile.TemporaryDirectory() as folder:
            empty, run = Path(folder) / "empty", Path(folder) / "run"
            empty.mkdir()
            result = subprocess.run([PYTHON, str(HERE / "gpu_run.py"), "unpack", str(empty), "--run", f"lite:{run}"],
                                    capture_output=True, text=True)
            self.assertNotEqual(result.returncode, 0)
            self.assertIn("did not come back", result.stderr)
            self.assertFalse(run.exists())


if __name__ == "__main__":
    unittest.main()

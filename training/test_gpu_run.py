"""The GPU round trip of training/gpu_run.py, at a tiny size on the CPU: pack a photo
folder, an ordinal set, disparity maps and two runs (lite, inpaint) into a carry folder,
run the device command there (with --device cpu: the teacher's labels first, then both
trainings), unpack what it wrote to $OUT, and do it again: the second runs resume. pack's
refusal of more than the device tool carries, and how it carries a teacher. And
train_depth.py's cosine learning-rate decay: its values, and a run resumed from a slim
checkpoint continuing the curve."""
import argparse
import contextlib
import io
import json
import re
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path
from unittest import mock

import numpy as np
import torch
from PIL import Image

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
PYTHON = sys.executable
sys.path.insert(0, str(HERE))
import gpu_run  # noqa: E402
import inpaint_data  # noqa: E402
import train_depth  # noqa: E402


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
                        "pairs": [{"a": [10.0, 290.0], "b": [899.0, 0.0], "label": "A", "votes": "AA"},
                                  {"a": [20.0, 20.0], "b": [30.0, 30.0], "label": "=", "votes": "A="}]})
    (root / "ordinal.json").write_text(json.dumps({"photos": entries}))


def make_disparity(folder: Path):
    """A 16-bit disparity map for every photo of make_photos, laid out as the inpainting
    data's cache: three bands and a disc, which slice into planes."""
    yy, xx = np.mgrid[0:300, 0:900]
    disparity = 10000 + 20000 * (yy // 100) + 12000 * ((xx - 450) ** 2 + (yy - 150) ** 2 < 60 ** 2)
    for i in range(10):
        path = Path(inpaint_data.disparity_path(str(folder), f"set/p{i}.jpg"))
        path.parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(disparity.astype(np.uint16)).save(path)


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
            make_disparity(tmp / "disparity")
            env = dict(os.environ, AMPI_PHOTO_ROOT=str(tmp / "photos"))
            carry, out = tmp / "carry", tmp / "out"
            # heavy trains by lite's code; its 12 MiB checkpoint beside these would pass the 64 MiB
            runs = {"lite": tmp / "lite", "inpaint": tmp / "inpaint"}
            run_args = [arg for model, run in runs.items() for arg in ("--run", f"{model}:{run}")]
            for round_trip in range(2):
                printed = self.run_tool("pack", *run_args, "--carry", str(carry), "--ordinal",
                                        str(tmp / "ordinal.json"), "--device", "cpu", "--python", PYTHON, "--size", "64x64",
                                        "--batch", "2", "--ordinal-batch", "2", "--minutes", "0.05",
                                        "--threads", "1", "--workers", "2", "--scene-reuse", "2", "--val-count", "2",
                                        "--lr-decay", "cosine", "--decay-steps", "1000", "--loss", "invariant", "--bf16",
                                        "--disparity-dir", str(tmp / "disparity"),
                                        "--teacher", "weights/depth_lite.ampw", "--teacher-weight", "0.5",
                                        "--teacher-resolutions", "64,96",
                                        "--inpaint-args=--max-photos 3 --batch 2 --crop 64 --log-every 2 "
                                        "--validate-every 2 --checkpoint-every 2", env=env)
                with Image.open(carry / "photos" / "set" / "p0.jpg") as photo:
                    self.assertEqual(photo.size, (384, 128))
                # the set is outside the working tree, so it is carried; train.sh scales it there
                self.assertEqual((carry / "ordinal_set" / "ordinal.json").read_text(),
                                 (tmp / "ordinal.json").read_text())
                self.assertFalse((carry / "ordinal.json").exists())
                self.check_plane_map(carry, tmp / "disparity")
                self.assertIn("--lr-decay cosine --decay-steps 1000", (carry / "train.sh").read_text())
                command = printed.strip().splitlines()[-1]
                shutil.rmtree(out, ignore_errors=True)
                out.mkdir()
                done = subprocess.run(["bash", "-c", command], cwd=ROOT, env=dict(env, OUT=str(out)),
                                      capture_output=True, text=True)
                self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
                self.check_scaled_ordinal_set(carry)
                self.check_teacher_labels(carry)
                self.run_tool("unpack", str(out), *run_args)
                for name in ("checkpoint.pt", "best.pt", "train.log"):
                    self.assertTrue((runs["lite"] / name).exists(), f"lite {name}")
                back = torch.load(out / "lite" / "checkpoint.pt")
                self.assertNotIn("optimiser", back)   # slim: under the 16 MiB a returned file may have
                self.assertIn("lr", back)
                self.assertEqual(next(iter(back["model"].values())).dtype, torch.float16)
                self.assertNotIn("ema", back)   # --ema 0.999: the average crosses as the weights
                for name in ("last.pt", "best.pt", "train.log", "log.csv"):
                    self.assertTrue((runs["inpaint"] / name).exists(), f"inpaint {name}")
                back = torch.load(out / "inpaint" / "last.pt")
                self.assertNotIn("opt_g", back)
                self.assertEqual(next(iter(back["generator"].values())).dtype, torch.float32)
            log = (runs["lite"] / "train.log").read_text()
            self.assertIn("initialised lite from weights/depth_lite.ampw", log)
            self.assertIn("(slim: Adam restarts)", log)
            self.assertIn("weights averaged (decay 0.999)", log)
            self.assertIn("rank weight 8, teacher", log)
            self.assertEqual(log.count("scale- and shift-invariant loss"), 2)
            self.assertEqual(log.count("bf16 autocast"), 2)
            self.assertIn("cosine decay from 1.00e-03 to 1.00e-05 at step 1000", log)
            self.assertEqual(log.count("stopped after 0.05 minutes"), 2)
            self.assertIn("ordinal_whdr", log)
            self.assertEqual(log.count(f"teacher's labels {carry}/teacher weight 0.5"), 2)
            self.check_inpaint_logs(runs["inpaint"])

    def check_scaled_ordinal_set(self, carry: Path):
        """train.sh scaled the set's points to the carried photos, 384 px long, and kept
        only the ordered pairs, each with its label and points (pixel centres scaled, kept
        inside the photo)."""
        packed = json.loads((carry / "ordinal.json").read_text())["photos"][0]
        self.assertEqual((packed["width"], packed["height"]), (384, 128))
        [pair] = packed["pairs"]
        self.assertEqual(set(pair), {"label", "a", "b"})
        scale = 384 / 900
        self.assertEqual(pair["a"], [round(10.5 * scale - 0.5, 1), round(290.5 * scale - 0.5, 1)])
        self.assertEqual(pair["b"], [383, round(0.5 * scale - 0.5, 1)])

    def test_the_bundled_ordinal_set_travels_with_the_tree(self):
        """pack carries no copy of training/ordinal/ordinal.json.gz (the working tree holds it),
        and refuses a set naming a photo it has not carried."""
        tracked = gpu_run.tracked_files()
        with tempfile.TemporaryDirectory() as folder:
            carry = Path(folder) / "carry"
            self.assertEqual(gpu_run.carried_file(gpu_run.ORDINAL, carry / "ordinal_set", "carry/ordinal_set", tracked),
                             "training/ordinal/ordinal.json.gz")
            self.assertFalse(carry.exists())
            make_photos(Path(folder))
            (Path(folder) / "photos" / "set" / "p3.jpg").unlink()
            with self.assertRaisesRegex(SystemExit, r"ordinal.json: set/p3.jpg is not under .*photos$"):
                gpu_run.scaled_ordinal_set(Path(folder) / "ordinal.json", Path(folder) / "photos")

    def check_teacher_labels(self, carry: Path):
        """The GPU machine labelled every carried photo with the carried teacher's
        ensemble, in a folder train_depth.py --teacher-labels reads."""
        lines = (carry / "teacher" / "labels.tsv").read_text().splitlines()
        self.assertEqual(lines[:3], ["ampi-distill\t1", "teacher\tdepth_lite.ampw\tampi.depth.dwt-mobilenetv3\tlite",
                                     "resolutions\t64,96\taspect kept"])
        self.assertEqual(lines[3], f"images\t{(carry / 'photos').resolve()}")
        self.assertEqual(sorted(lines[4:]), [f"set_p{i}.npy\tset/p{i}.jpg" for i in range(10)])
        label = np.load(carry / "teacher" / "set_p0.npy")
        self.assertEqual(label.shape, (128, 384))
        self.assertGreaterEqual(float(label.min()), 0.0)   # [0, 1] at the ensemble's size, then resized
        self.assertGreater(float(label.max() - label.min()), 0.9)
        self.assertFalse((carry / "teacher_weights").exists())   # the bundled file travels with the tree
        self.assertIn("--teacher-checkpoint weights/depth_lite.ampw", (carry / "train.sh").read_text())

    def check_plane_map(self, carry: Path, disparity: Path):
        """A carried plane map is what the inpainting data slices from the map at the
        carried photo's size."""
        with Image.open(carry / "inpaint_planes" / "set" / "p0.jpg.png") as image:
            planes = np.asarray(image)
        disparity_map = inpaint_data.load_disparity(str(disparity / "set" / "p0.jpg.png"), (384, 128))
        sliced = inpaint_data.slice_labels(disparity_map)
        np.testing.assert_array_equal(planes, sliced)
        self.assertGreater(planes.max(), 0)

    def check_inpaint_logs(self, run: Path):
        log = (run / "train.log").read_text()
        self.assertEqual(log.count("generator starts from weights/inpaint.ampw"), 1)
        self.assertIn("(slim: Adam restarts)", log)
        self.assertEqual(log.count("prepared 3 sliced photos from 3 (0 with the stand-in disparity)"), 2)
        self.assertEqual(log.count("stopped after 0.05 minutes"), 2)
        rows = (run / "log.csv").read_text().splitlines()
        self.assertTrue(rows[0].startswith("step,") and not any(r.startswith("step,") for r in rows[1:]))
        steps = [int(row.split(",")[0]) for row in rows[1:]]
        self.assertEqual(steps, sorted(set(steps)))   # the second run continued the first's steps
        self.assertGreater(steps[-1], 2)

    def test_pack_refuses_more_than_the_device_tool_carries(self):
        with tempfile.TemporaryDirectory() as folder:
            tmp = Path(folder)
            make_photos(tmp)
            with mock.patch.dict(os.environ, AMPI_PHOTO_ROOT=str(tmp / "photos")), \
                    mock.patch.object(gpu_run, "TRANSFER_LIMIT", 2 ** 20), contextlib.redirect_stdout(io.StringIO()), \
                    self.assertRaises(SystemExit) as refused:
                gpu_run.main(["pack", "--run", f"inpaint:{tmp / 'inpaint'}", "--carry", str(tmp / "carry"),
                              "--ordinal", str(tmp / "ordinal.json")])
            message = str(refused.exception)
            self.assertIn("more than the device tool's 1 MiB", message)
            self.assertRegex(message, r"photos \d+\.\d,")   # each part named, with its size
            self.assertNotIn("\n", message)

    def test_the_training_ends_before_the_call_does(self):
        """train.sh trains --minutes, or less when the call's limit (--call-seconds) leaves
        less before the hand-back; `echo` stands in for Python, so its console shows the
        command line each run was given."""
        with tempfile.TemporaryDirectory() as folder:
            tmp = Path(folder)
            make_photos(tmp)
            env = dict(os.environ, AMPI_PHOTO_ROOT=str(tmp / "photos"), OUT=str(tmp / "out"))
            for call_seconds, longest in ((600, 5.0), (gpu_run.HANDBACK_SECONDS + 6, 0.1)):
                self.run_tool("pack", "--run", f"lite:{tmp / 'lite'}", "--carry", str(tmp / "carry"), "--ordinal",
                              str(tmp / "ordinal.json"), "--python", "echo", "--minutes", "5",
                              "--call-seconds", str(call_seconds), env=env)
                done = subprocess.run(["bash", str(tmp / "carry" / "train.sh")], cwd=ROOT, env=env,
                                      capture_output=True, text=True)
                self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
                given = re.search(r"--minutes (\S+)", (tmp / "carry" / "lite" / "console.txt").read_text())
                self.assertTrue(0 < float(given[1]) <= longest and float(given[1]) > longest - 0.05, given[1])
            with contextlib.redirect_stdout(io.StringIO()), self.assertRaisesRegex(SystemExit, "no time to train"):
                gpu_run.main(["pack", "--run", f"lite:{tmp / 'lite'}", "--carry", str(tmp / "carry"),
                              "--call-seconds", str(gpu_run.HANDBACK_SECONDS)])

    def test_a_bundled_teacher_travels_with_the_tree_any_other_is_carried(self):
        with tempfile.TemporaryDirectory() as folder:
            tmp = Path(folder)
            teacher, carry = tmp / "teacher.ampw", tmp / "carry"
            teacher.write_bytes(b"weights")
            carry.mkdir()
            args = argparse.Namespace(teacher=str(teacher), carry="carry")
            tracked = gpu_run.tracked_files()
            self.assertEqual(gpu_run.carried_teacher(args, carry, tracked), "carry/teacher_weights/teacher.ampw")
            self.assertEqual((carry / "teacher_weights" / "teacher.ampw").read_bytes(), b"weights")
            with contextlib.redirect_stdout(io.StringIO()), self.assertRaisesRegex(SystemExit, "for depth runs"):
                gpu_run.main(["pack", "--run", f"inpaint:{tmp / 'inpaint'}", "--carry", str(carry),
                              "--teacher", str(teacher)])
            for wrong in (tmp / "missing.ampw", tmp / "checkpoint.pt"):
                with self.assertRaisesRegex(SystemExit, "expected a depth network's .ampw file"):
                    gpu_run.carried_teacher(argparse.Namespace(teacher=str(wrong), carry="carry"), carry, tracked)
            bundled = argparse.Namespace(teacher=str(gpu_run.ROOT / "weights" / "depth_lite.ampw"), carry="carry")
            self.assertEqual(gpu_run.carried_teacher(bundled, carry, tracked), "weights/depth_lite.ampw")

    def test_unpack_without_files_leaves_the_run_alone(self):
        with tempfile.TemporaryDirectory() as folder:
            empty, run = Path(folder) / "empty", Path(folder) / "run"
            empty.mkdir()
            result = subprocess.run([PYTHON, str(HERE / "gpu_run.py"), "unpack", str(empty), "--run", f"lite:{run}"],
                                    capture_output=True, text=True)
            self.assertNotEqual(result.returncode, 0)
            self.assertIn("did not come back", result.stderr)
            self.assertFalse(run.exists())


class LearningRateDecay(unittest.TestCase):
    def test_cosine_values(self):
        args = argparse.Namespace(lr=1e-3, decay_steps=100)
        for step, lr in ((0, 1e-3), (50, (1e-3 + 1e-5) / 2), (100, 1e-5), (250, 1e-5)):
            self.assertAlmostEqual(train_depth.cosine_lr(args, step), lr, places=12)
        self.assertAlmostEqual(train_depth.cosine_lr(args, 25), 1e-5 + 0.99e-3 * (0.5 + 0.5 ** 1.5), places=12)

    def test_a_resumed_run_continues_the_curve(self):
        """Steps 1-3, then steps 4-7 from the slim checkpoint with a stale learning rate in
        it: every step trains at the curve's rate for its step."""
        with tempfile.TemporaryDirectory() as folder:
            tmp = Path(folder)
            make_photos(tmp)
            env = dict(os.environ, AMPI_PHOTO_ROOT=str(tmp / "photos"))
            run = tmp / "run"
            common = ["--model", "lite", "--run", str(run), "--data", "scenes", "--size", "64x64", "--batch", "1",
                      "--lr-decay", "cosine", "--decay-steps", "5", "--workers", "0", "--log-every", "1",
                      "--val-every", "100", "--val-count", "1", "--checkpoint-every", "100"]

            def train(steps: int):
                done = subprocess.run([PYTHON, str(HERE / "train_depth.py"), *common, "--steps", str(steps)],
                                      cwd=ROOT, env=env, capture_output=True, text=True)
                self.assertEqual(done.returncode, 0, done.stderr)

            train(3)
            subprocess.run([PYTHON, str(HERE / "gpu_run.py"), "slim", str(run / "checkpoint.pt"),
                            str(run / "checkpoint.pt")], check=True)
            slim = torch.load(run / "checkpoint.pt")
            slim["lr"] = 0.5
            torch.save(slim, run / "checkpoint.pt")
            train(7)
            log = (run / "train.log").read_text()
            self.assertIn("(slim: Adam restarts)", log)
            logged = {int(step): lr for step, lr in re.findall(r"^\S+ \S+ step (\d+) loss .* lr (\S+)", log, re.M)}
            curve = argparse.Namespace(lr=1e-3, decay_steps=5)
            self.assertEqual(logged, {step: f"{train_depth.cosine_lr(curve, step - 1):.2e}" for step in range(1, 8)})


if __name__ == "__main__":
    unittest.main()

"""Checks our Depth Anything V2 twin (depth_anything.py) against the official code.

    # the official repository, outside this one (github DepthAnything/Depth-Anything-V2):
    git clone https://github.com/DepthAnything/Depth-Anything-V2 /tmp/dav2
    nice -n 5 /usr/bin/python3 training/check_depth_anything.py /tmp/dav2 [--variants vits vitb]

For each variant the official `DepthAnythingV2` is built, given seeded random weights
(`depth_anything.randomise_`: every parameter random, LayerScale and LayerNorm away from
1), and its state dict is loaded strictly into the twin, once as it is and once with
LayerScale folded into the weights (what import_depth_anything.py writes). Then both run:

  - the network alone on the same normalised 518x518 input;
  - the official `infer_image` (OpenCV BGR uint8 in, cv2 INTER_CUBIC resize, output back
    to the photo's size) against the twin's `infer` on the same photo as RGB, for
    synthetic photos of 518x518, 480x640 and 333x500 (H x W);
  - the preprocessing alone (official `image2tensor` against `preprocess`).

Each line gives the largest absolute difference and that divided by the official
output's range (max - min). Needs OpenCV's Python module (Debian: python3-opencv); the
official code imports torchvision only for `Compose`, which is stubbed when absent;
xformers is optional there and not used.
"""
from __future__ import annotations

import argparse
import sys
import time
import types
from pathlib import Path

import numpy as np
import torch

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import depth_anything as dav2  # noqa: E402
from make_depth_fixtures import test_image  # noqa: E402

SEED = 20240613
PHOTOS = ((518, 518), (480, 640), (333, 500))  # H x W


def stub_torchvision():
    """A minimal `torchvision.transforms.Compose` (apply in order) if torchvision is absent."""
    try:
        import torchvision  # noqa: F401
        return False
    except ImportError:
        pass

    class Compose:
        def __init__(self, transforms):
            self.transforms = transforms

        def __call__(self, sample):
            for t in self.transforms:
                sample = t(sample)
            return sample

    transforms = types.ModuleType("torchvision.transforms")
    transforms.Compose = Compose
    package = types.ModuleType("torchvision")
    package.transforms = transforms
    sys.modules.update({"torchvision": package, "torchvision.transforms": transforms})
    return True


def official_model(repo: str, variant: str):
    """The official model of a variant, with the widths its run.py uses."""
    sys.path.insert(0, repo)
    from depth_anything_v2.dpt import DepthAnythingV2
    cfg = dav2.VARIANTS[variant]
    return DepthAnythingV2(encoder=variant, features=cfg.features, out_channels=list(cfg.out_channels))


def difference(reference: np.ndarray, ours: np.ndarray) -> str:
    span = float(reference.max() - reference.min())
    err = float(np.abs(reference.astype(np.float64) - ours).max())
    return f"max |diff| {err:.3e}, range {span:.4g}, relative {err / max(span, 1e-30):.2e}"


def check_variant(repo: str, variant: str):
    torch.manual_seed(SEED)
    official = dav2.randomise_(official_model(repo, variant), SEED).eval()
    state = official.state_dict()
    twin = dav2.build(variant)
    twin.load_state_dict(state, strict=True)
    folded = dav2.build(variant)
    folded.load_state_dict(dav2.fold_layer_scale(state), strict=True)
    print(f"{variant}: {len(state)} tensors, {sum(t.numel() for t in state.values()):,} parameters; "
          "state dict loads strictly")

    x = torch.randn(1, 3, 518, 518, generator=torch.Generator().manual_seed(SEED))
    with torch.no_grad():
        ref = official(x).numpy()
        print(f"  network 518x518:           twin {difference(ref, twin(x).numpy())}")
        print(f"  network 518x518:         folded {difference(ref, folded(x).numpy())}")
    for i, (h, w) in enumerate(PHOTOS):
        rgb = (test_image(h, w, SEED + i) * 255.0 + 0.5).astype(np.uint8)
        bgr = np.ascontiguousarray(rgb[:, :, ::-1])
        start = time.time()
        ref = official.infer_image(bgr, 518)
        seconds = time.time() - start
        shape = dav2.working_shape(h, w)
        name = f"infer_image {h}x{w} -> {shape[0]}x{shape[1]}"
        inp_ref = official.image2tensor(bgr, 518)[0].numpy()
        inp = dav2.preprocess(rgb).numpy()
        print(f"  {name}: preprocess {difference(inp_ref, inp)}")
        print(f"  {name}:       twin {difference(ref, dav2.infer(twin, rgb))} ({seconds:.1f} s official)")
        print(f"  {name}:     folded {difference(ref, dav2.infer(folded, rgb))}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("official", help="a checkout of github.com/DepthAnything/Depth-Anything-V2")
    p.add_argument("--variants", nargs="+", default=["vits", "vitb"], choices=sorted(dav2.VARIANTS))
    p.add_argument("--threads", type=int, default=2)
    args = p.parse_args(argv)
    if not (Path(args.official) / "depth_anything_v2" / "dpt.py").is_file():
        sys.exit(f"{args.official}: not a Depth-Anything-V2 checkout (no depth_anything_v2/dpt.py)")
    torch.set_num_threads(args.threads)
    stubbed = stub_torchvision()
    print(f"torch {torch.__version__}, numpy {np.__version__}, seed {SEED}, {args.threads} threads"
          + (", torchvision stubbed (Compose only)" if stubbed else ""))
    for variant in args.variants:
        check_variant(args.official, variant)


if __name__ == "__main__":
    main()

#!/usr/bin/env bash
# The whole ampi program cross-built for aarch64 (scripts/arm64_sysroot.sh, the sysroot
# build of scripts/test.sh) runs `ampi run` on a small photo under qemu, and its depth map
# and layers match the x86 build's within one 8-bit level: the same pipeline on another
# ISA (NEON kernels, the NEON compositor) and against Debian's arm64 OpenCV.
#   usage: arm64_run.sh ARM_AMPI X86_AMPI SYSROOT
set -euo pipefail
arm=$1 x86=$2 sysroot=$3
cd "$(dirname "$0")/../.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

/usr/bin/python3 - "$tmp/photo.jpg" <<'PY'
import sys
from PIL import Image
photo = Image.open("examples/forest_path.jpg").convert("RGB")
photo.thumbnail((256, 256))
photo.save(sys.argv[1], quality=95)
PY
options=(--frames 6 --threads 2 --quiet)
export AMPI_WEIGHTS_DIR=$PWD/weights
"$x86" run "$tmp/photo.jpg" -o "$tmp/x86" "${options[@]}"
start=$(date +%s)
qemu-aarch64 -L "$sysroot" "$arm" run "$tmp/photo.jpg" -o "$tmp/arm" "${options[@]}"
echo "ampi run under qemu-aarch64: $(($(date +%s) - start)) s"

/usr/bin/python3 - "$tmp/x86" "$tmp/arm" <<'PY'
import json, sys
import numpy as np
from PIL import Image
x86, arm = sys.argv[1:]
def image(folder, name):
    return np.asarray(Image.open(f"{folder}/{name}"), dtype=np.int64)
failures = []
depth = np.abs(image(x86, "depth.png") - image(arm, "depth.png")).max()
if depth > 257:  # 16-bit map: one 8-bit level
    failures.append(f"depth.png differs by {depth} of 65535")
planes = [json.load(open(f"{f}/mpi/mpi.json"))["planes"] for f in (x86, arm)]
if len(planes[0]) != len(planes[1]):
    failures.append(f"{len(planes[0])} planes on x86, {len(planes[1])} on arm64")
for a, b in zip(*planes):
    diff = np.abs(image(f"{x86}/mpi", a["layer"]) - image(f"{arm}/mpi", b["layer"])).max()
    if diff > 1:
        failures.append(f"{a['layer']} differs by {diff} levels")
import os
if os.path.getsize(f"{arm}/video.mp4") == 0:
    failures.append("empty video.mp4")
print("\n".join(failures) or f"arm64 run matches x86: depth within {depth}/65535, {len(planes[0])} layers within one level")
sys.exit(1 if failures else 0)
PY

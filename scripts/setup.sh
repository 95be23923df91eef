#!/usr/bin/env bash
# Installs everything ampi needs on a fresh Debian 12 machine. Idempotent: packages that
# are already present are skipped, so it is cheap to run before every build.
set -euo pipefail

packages=(
  build-essential cmake pkg-config          # C++17 toolchain (g++ 12)
  libopencv-dev                             # the only C++ library: image/video I/O, filters
  catch2                                    # unit tests (Catch2 v2)
  python3-numpy python3-torch               # fixtures, training, export (Debian's CPU torch)
  python3-pil                               # JPEG decoding of the photos (training/photo_folder.py)
  g++-aarch64-linux-gnu qemu-user           # aarch64 cross build, tests run under qemu
  debootstrap                               # the arm64 sysroot of the whole program (scripts/arm64_sysroot.sh)
  ffmpeg                                    # GIF output (palette) and the MP4s (x264 held to bounded memory)
  clang libclang-rt-14-dev                  # libFuzzer targets (fuzz/, scripts/test_reliability.sh)
  chromium                                  # headless screenshots of viewer.html in the tests
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The peer benchmark's ONNX Runtime (bench/peers/run.sh): npm's onnxruntime-node at the
# locked version, its bundled CPU library only (ONNXRUNTIME_NODE_INSTALL=skip: no CUDA
# download). Re-installed only when the lock file is newer than the installed tree.
peers="$(cd "$(dirname "$0")/.." && pwd)/bench/peers"
if [ "$peers/package-lock.json" -nt "$peers/node_modules/.package-lock.json" ]; then
  if ! command -v npm >/dev/null; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends nodejs npm
  fi
  (cd "$peers" && ONNXRUNTIME_NODE_INSTALL=skip npm ci --no-audit --no-fund)
fi

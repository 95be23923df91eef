#!/usr/bin/env bash
# The peer benchmark in one command: installs what is missing (scripts/setup.sh: Debian
# packages and this folder's onnxruntime-node), builds ampi and the OpenCV DNN peer,
# exports the lite and heavy networks to ONNX (BatchNorm folded), times ampi, ONNX
# Runtime, OpenCV DNN and PyTorch side by side and writes bench/RESULTS.md.
#
#   bash bench/peers/run.sh                      # everything (several minutes on 2 cores)
#   bash bench/peers/run.sh --models lite --sizes 1024x768:5   # a subset (run_peers.py --help)
#
# Build folder: $AMPI_BUILD_DIR (default build-peers); exports, inputs and outputs go to
# out/peers/ (both git-ignored).
set -euo pipefail
cd "$(dirname "$0")/../.."
bash scripts/setup.sh

build="${AMPI_BUILD_DIR:-build-peers}"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$(nproc)" --target ampi ampi_peer_opencv_dnn

/usr/bin/python3 bench/peers/run_peers.py --ampi "$build/ampi" \
  --opencv-peer "$build/ampi_peer_opencv_dnn" --work out/peers "$@"

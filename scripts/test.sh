#!/usr/bin/env bash
# Builds ampi and runs every test: the native build (every ISA this CPU runs), then the
# aarch64 cross build under qemu. Installs what it needs first (scripts/setup.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

jobs=$(nproc)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

# aarch64: the inference core (engine, kernels, weights_format, nets, and the slicer's and
# the compositor's SIMD kernels; no OpenCV) cross built with g++-aarch64-linux-gnu. ctest
# runs each test binary under qemu-aarch64 (the toolchain's CMAKE_CROSSCOMPILING_EMULATOR),
# which makes NEON the best ISA there: the kernels test (tests/kernels/) holds every SIMD
# family's NEON-against-scalar checks. qemu is about 150x slower on float code, so the
# tests take their small shapes.
cmake -S . -B build-aarch64 -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake -DAMPI_WITH_OPENCV=OFF
cmake --build build-aarch64 -j"$jobs"
AMPI_TEST_SMALL=1 ctest --test-dir build-aarch64 --output-on-failure --no-tests=error \
  -R '^(engine|kernels|weights_format|nets)$' -j"$jobs"

# Sanitizers (ASan+UBSan, TSan) and bounded libFuzzer runs of every parser: RELIABILITY.md.
bash scripts/test_reliability.sh

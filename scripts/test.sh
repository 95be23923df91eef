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

# aarch64: the whole program cross built with g++-aarch64-linux-gnu against an arm64
# Debian sysroot (scripts/arm64_sysroot.sh: Debian's own arm64 packages, OpenCV included).
# ctest runs the inference core's test binaries (engine, kernels, weights_format, nets; the
# kernels test holds every SIMD family's NEON-against-scalar checks, the slicer's and the
# compositor's included) under qemu-aarch64 (the toolchain's CMAKE_CROSSCOMPILING_EMULATOR),
# which makes NEON the best ISA there; qemu is about 150x slower on float code, so the
# tests take their small shapes. Then `ampi run` itself runs under qemu and must match the
# x86 run, and the board package is made and its installed layout checked.
bash scripts/arm64_sysroot.sh build-aarch64-sysroot
cmake -S . -B build-aarch64 -DCMAKE_BUILD_TYPE=Release -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake \
  -DAMPI_ARM64_SYSROOT="$PWD/build-aarch64-sysroot" -DAMPI_WITH_OPENCV=ON
cmake --build build-aarch64 -j"$jobs" --target ampi test_engine test_kernels test_weights_format test_nets
AMPI_TEST_SMALL=1 ctest --test-dir build-aarch64 --output-on-failure --no-tests=error \
  -R '^(engine|kernels|weights_format|nets)$' -j"$jobs"
bash tests/cli/arm64_run.sh build-aarch64/ampi build/ampi build-aarch64-sysroot
bash scripts/package_arm64.sh build-aarch64 build-aarch64-sysroot
bash tests/cli/arm64_package.sh dist/ampi_*_arm64.deb build-aarch64-sysroot

# Sanitizers (ASan+UBSan, TSan) and bounded libFuzzer runs of every parser: RELIABILITY.md.
bash scripts/test_reliability.sh

#!/usr/bin/env bash
# Sets up, builds, and turns the bundled example photo into a 3D photo:
# out/forest_path/{depth.png, mpi/, video.mp4, viewer.html}.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target ampi
mkdir -p out
./build/ampi run examples/forest_path.jpg -o out/forest_path --force "$@"
echo "open out/forest_path/viewer.html in a browser, or play out/forest_path/video.mp4"

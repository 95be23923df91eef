#!/usr/bin/env bash
# The board package (scripts/package_arm64.sh) unpacked as dpkg would install it: its
# /usr/bin/ampi runs under qemu and finds the bundled weights in /usr/share/ampi/weights
# on its own, with no AMPI_WEIGHTS_DIR.
#   usage: arm64_package.sh PACKAGE.deb SYSROOT
set -euo pipefail
deb=$1 sysroot=$2
cd "$(dirname "$0")/../.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
dpkg-deb -x "$deb" "$tmp/root"
for file in usr/bin/ampi usr/share/ampi/weights/depth_lite.ampw usr/share/ampi/weights/inpaint.ampw; do
  [ -f "$tmp/root/$file" ] || { echo "$deb: no /$file" >&2; exit 1; }
done
dpkg-deb -f "$deb" Depends | grep -q "libopencv-core" || { echo "$deb: Depends names no OpenCV" >&2; exit 1; }
dpkg-deb -f "$deb" Recommends | grep -qw "ffmpeg" || { echo "$deb: Recommends lacks ffmpeg (bounded-memory MP4s)" >&2; exit 1; }
unset AMPI_WEIGHTS_DIR
qemu-aarch64 -L "$sysroot" "$tmp/root/usr/bin/ampi" depth tests/fixtures/slicing/three_levels.png \
  -o "$tmp/depth.png" --threads 2 >/dev/null
[ -s "$tmp/depth.png" ] || { echo "installed ampi wrote no depth map" >&2; exit 1; }
echo "package $deb: installed layout runs, bundled weights found"

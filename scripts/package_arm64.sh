#!/usr/bin/env bash
# Packs the aarch64 build of ampi for a board as a Debian package:
#   scripts/package_arm64.sh [BUILD_DIR] [SYSROOT]   -> dist/ampi_VERSION_arm64.deb
# (defaults build-aarch64 and build-aarch64-sysroot, as scripts/test.sh makes them).
# The package holds /usr/bin/ampi and the bundled weights in /usr/share/ampi/weights (where
# an installed ampi looks, nets/bundled_weights.h) and depends on Debian 12's arm64
# OpenCV runtime libraries, the only libraries ampi links besides the C and C++ runtimes.
# It recommends the ffmpeg program, which apt installs by default: ampi pipes its MP4s to
# it with x264's memory bounded (render/video_out.h); OpenCV's own writer, used without
# it, lets x264 take about 1.5 GB at 4K, too much for a 2 GB board:
#   sudo apt install ./ampi_VERSION_arm64.deb
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-aarch64} sysroot=${2:-build-aarch64-sysroot}
version=$(sed -n 's/^project(ampi VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
[ -x "$build/ampi" ] || { echo "$build/ampi: not built (see README: building for a board)" >&2; exit 1; }

# The OpenCV modules ampi links, as Debian 12 packages them (libopencv-<module>406); each
# must be one the sysroot was made from, so the names cannot drift from what was linked.
depends=(libc6 libstdc++6 libgcc-s1)
for module in core imgproc imgcodecs videoio photo; do
  deb=$(ls "$sysroot"/var/cache/apt/archives/libopencv-"$module"[0-9]*_arm64.deb 2>/dev/null | head -1)
  [ -n "$deb" ] || { echo "$sysroot: no libopencv-$module package (make it with scripts/arm64_sysroot.sh)" >&2; exit 1; }
  depends+=("$(basename "$deb" | cut -d_ -f1)")
done

stage=$(mktemp -d)
chmod 755 "$stage"
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/DEBIAN" "$stage/usr/bin" "$stage/usr/share/ampi/weights"
aarch64-linux-gnu-strip -o "$stage/usr/bin/ampi" "$build/ampi"
cp weights/*.ampw "$stage/usr/share/ampi/weights/"
cat >"$stage/DEBIAN/control" <<CONTROL
Package: ampi
Version: $version
Architecture: arm64
Maintainer: ampi developers
Depends: $(IFS=,; echo "${depends[*]}" | sed 's/,/, /g')
Recommends: ffmpeg
Installed-Size: $(du -sk "$stage/usr" | cut -f1)
Section: graphics
Priority: optional
Description: single-photo 3D: adaptive multiplane images and parallax videos
 ampi turns one photograph into an adaptive multiplane image and renders new views of
 it (parallax videos, stereo pairs, a web viewer), on its own NEON kernels.
CONTROL
mkdir -p dist
out=dist/ampi_${version}_arm64.deb
dpkg-deb --root-owner-group --build "$stage" "$out" >/dev/null
echo "$out ($(du -h "$out" | cut -f1)): depends on ${depends[*]}"

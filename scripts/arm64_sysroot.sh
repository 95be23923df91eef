#!/usr/bin/env bash
# Makes an arm64 Debian 12 sysroot for cross-building the whole ampi program (OpenCV
# included) and running it under qemu: scripts/arm64_sysroot.sh DIR (default
# build-aarch64-sysroot). Debian's arm64 libopencv-dev cannot be installed beside the
# amd64 one, so the sysroot is a folder of its own, made from Debian's own arm64 packages:
# debootstrap's first stage downloads them (no arm64 code runs), every downloaded .deb is
# unpacked into the folder, and the links that dpkg's alternatives would make are made by
# hand. Idempotent: a finished sysroot is left as it is. About 1.5 GB.
set -euo pipefail
dir=${1:-build-aarch64-sysroot}
mirror=${AMPI_DEBIAN_MIRROR:-http://deb.debian.org/debian}
[ -f "$dir/.ampi-sysroot-complete" ] && exit 0

command -v debootstrap >/dev/null || [ -x /usr/sbin/debootstrap ] ||
  { echo "arm64_sysroot.sh: needs debootstrap (bash scripts/setup.sh)" >&2; exit 1; }
# debootstrap makes device nodes and owners in the tree: root's work
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"

$SUDO rm -rf "$dir"
$SUDO mkdir -p "$dir"
echo "arm64 sysroot: downloading Debian 12 arm64 packages into $dir"
log=$(mktemp)
$SUDO env PATH="$PATH:/usr/sbin:/sbin" debootstrap --arch=arm64 --foreign --variant=minbase \
  --include=libopencv-dev,libstdc++-12-dev bookworm "$dir" "$mirror" >"$log" 2>&1 || { tail -20 "$log"; exit 1; }
rm -f "$log"
for deb in "$dir"/var/cache/apt/archives/*.deb; do $SUDO dpkg -x "$deb" "$dir"; done
# libopencv-core links against libblas.so.3 and liblapack.so.3, which Debian provides
# through the alternatives system (dpkg never ran here).
lib="$dir/usr/lib/aarch64-linux-gnu"
$SUDO ln -sf blas/libblas.so.3 "$lib/libblas.so.3"
$SUDO ln -sf lapack/liblapack.so.3 "$lib/liblapack.so.3"
$SUDO touch "$dir/.ampi-sysroot-complete"
echo "arm64 sysroot: $dir ($(du -sh "$dir" | cut -f1))"

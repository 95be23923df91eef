#!/bin/sh
# ampi run end to end: a photo gives every output (a video with all its frames); bad
# photos each give one line on stderr, a non-zero exit and no output folder; an existing
# folder is refused without --force and, with it, keeps the user's other files.
#   usage: run_cli.sh AMPI_BINARY PHOTO
set -u
ampi=$1
photo=$2
. "$(dirname "$0")/../support/cli_checks.sh"

# expect_error NAME PHOTO TEXT
expect_error() {
  before=$failures
  "$ampi" run "$2" -o "$tmp/out_$1" --frames 4 >"$tmp/stdout" 2>"$tmp/err"
  status=$?
  [ "$status" -ne 0 ] || fail "$1: exit status 0"
  lines=$(wc -l <"$tmp/err")
  [ "$lines" -eq 1 ] || fail "$1: $lines lines on stderr: $(cat "$tmp/err")"
  grep -qF "$3" "$tmp/err" || fail "$1: stderr lacks '$3': $(cat "$tmp/err")"
  [ ! -e "$tmp/out_$1" ] || fail "$1: left an output folder"
  [ -z "$(ls -A "$tmp" | grep '^\.ampi-staging')" ] || fail "$1: left a staging folder"
  [ "$failures" -ne "$before" ] || echo "ok: $1 -> $(cat "$tmp/err")"
}

echo "not an image" >"$tmp/text.jpg"
: >"$tmp/empty.jpg"
size=$(wc -c <"$photo")
head -c $((size / 2)) "$photo" >"$tmp/truncated.jpg"
mkdir "$tmp/folder.jpg"
expect_error text "$tmp/text.jpg" "$tmp/text.jpg: not a readable image"
expect_error empty "$tmp/empty.jpg" "$tmp/empty.jpg: empty file"
expect_error truncated "$tmp/truncated.jpg" "$tmp/truncated.jpg: truncated JPEG"
expect_error missing "$tmp/missing.jpg" "$tmp/missing.jpg: no such file"

# A folder argument stands for the photos in it: this one holds none.
"$ampi" run "$tmp/folder.jpg" -o "$tmp/out_dir" >/dev/null 2>"$tmp/err" && fail "folder: exit 0"
grep -qF "holds no photos" "$tmp/err" || fail "folder: $(cat "$tmp/err")"

# The real thing, at a small working size to keep the test short.
out="$tmp/good"
"$ampi" run "$photo" -o "$out" --frames 12 --working-size 256 --quiet 2>"$tmp/err" ||
  fail "good photo: exit $?: $(cat "$tmp/err")"
for f in depth.png mpi/mpi.json mpi/layer_00.png video.mp4 viewer.html; do
  [ -s "$out/$f" ] || fail "good photo: $f missing or empty"
done
if command -v ffprobe >/dev/null; then
  frames=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames \
           -of csv=p=0 "$out/video.mp4")
  [ "$frames" = 12 ] || fail "video has $frames frames, not 12"
fi

# An existing folder: refused without --force; with it, only ampi's outputs change.
echo mine >"$out/notes.txt"
"$ampi" run "$photo" -o "$out" --frames 2 --working-size 256 --quiet 2>"$tmp/err" &&
  fail "existing folder accepted without --force"
grep -qF "already exists" "$tmp/err" || fail "existing folder: $(cat "$tmp/err")"
"$ampi" run "$photo" -o "$out" --frames 2 --working-size 256 --quiet --force 2>"$tmp/err" ||
  fail "--force: exit $?: $(cat "$tmp/err")"
[ "$(cat "$out/notes.txt")" = mine ] || fail "--force touched the user's notes.txt"

[ "$failures" -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "all run checks passed"

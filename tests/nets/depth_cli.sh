#!/bin/sh
# ampi depth end to end: a 16-bit grey PNG of the photo's own size from the bundled
# weights and from a Depth Anything V2 file, and one-line errors (non-zero exit, no
# output left) for bad input.
#   usage: depth_cli.sh AMPI_BINARY PHOTO
set -u
ampi=$1
photo=$2
. "$(dirname "$0")/../support/cli_checks.sh"
echo "not an image" >"$tmp/text.jpg"

# png_header FILE: "width height bit_depth colour_type" from the IHDR chunk.
png_header() {
  od -An -tu1 -j16 -N10 "$1" | awk '{ print $1*16777216 + $2*65536 + $3*256 + $4, $5*16777216 + $6*65536 + $7*256 + $8, $9, $10 }'
}

# The map must have the photo's size (forest_path.jpg is 1024x640): a small working
# resolution keeps the test fast and checks the resize back to the photo's size.
for model in lite heavy; do
  out="$tmp/$model.png"
  if "$ampi" depth "$photo" -o "$out" --model "$model" --max-size 128 --threads 2 >"$tmp/log" 2>&1; then
    header=$(png_header "$out")
    size=$(sed -n 's/.*: \([0-9]*\)x\([0-9]*\) disparity.*/\1 \2/p' "$tmp/log")
    [ "$header" = "$size 16 0" ] || fail "$model: PNG header '$header', expected '$size 16 0' (log: $(cat "$tmp/log"))"
    [ "$size" = "1024 640" ] || fail "$model: reported size '$size', the photo is 1024x640"
  else
    fail "$model: exit status $?: $(cat "$tmp/log")"
  fi
done

# Depth Anything V2 (the tiny random-weight fixture) through the same command: a map of
# the photo's size at a small working size, and `ampi info` names the model.
dav2="$(dirname "$0")/../fixtures/nets/dav2_tiny.ampw"
if "$ampi" depth "$photo" -o "$tmp/dav2.png" --weights "$dav2" --working-size 28 --threads 2 >"$tmp/log" 2>&1; then
  header=$(png_header "$tmp/dav2.png")
  [ "$header" = "1024 640 16 0" ] || fail "dav2: PNG header '$header', expected '1024 640 16 0'"
  grep -qF "working size 28" "$tmp/log" || fail "dav2: log lacks the working size: $(cat "$tmp/log")"
else
  fail "dav2: exit status $?: $(cat "$tmp/log")"
fi
"$ampi" info "$dav2" >"$tmp/info" 2>&1 || fail "dav2 info: exit status $?: $(cat "$tmp/info")"
grep -qF "model: ampi.depth.dav2-vit-dpt, variant tiny, 41609 parameters, working size 56" "$tmp/info" ||
  fail "dav2 info: no model line: $(head -3 "$tmp/info")"

# expect_error NAME TEXT ARGS...: non-zero exit, one stderr line containing TEXT, no output.
expect_error() {
  name=$1
  text=$2
  shift 2
  rm -f "$tmp/bad.png"
  "$ampi" depth "$@" >"$tmp/out" 2>"$tmp/err"
  status=$?
  [ "$status" -ne 0 ] || fail "$name: exit status 0"
  [ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "$name: stderr is not one line: $(cat "$tmp/err")"
  grep -qF -e "$text" "$tmp/err" || fail "$name: stderr lacks '$text': $(cat "$tmp/err")"
  [ ! -e "$tmp/bad.png" ] || fail "$name: left $tmp/bad.png behind"
}

expect_error "missing photo" "$tmp/none.jpg: " "$tmp/none.jpg" -o "$tmp/bad.png"
expect_error "not a photo" "$tmp/text.jpg: " "$tmp/text.jpg" -o "$tmp/bad.png"
expect_error "no output" "missing -o" "$photo"
expect_error "bad model" "--model: 'medium'" "$photo" -o "$tmp/bad.png" --model medium
expect_error "bad max size" "--max-size: '0'" "$photo" -o "$tmp/bad.png" --max-size 0
expect_error "bad working size" "--working-size: working size 5 is not in 14..16384" "$photo" -o "$tmp/bad.png" \
  --weights "$dav2" --working-size 5
expect_error "not depth weights" "$tmp/text.jpg: " "$photo" -o "$tmp/bad.png" --weights "$tmp/text.jpg"

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "ampi depth: all checks passed"

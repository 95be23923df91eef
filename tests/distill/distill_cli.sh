#!/bin/sh
# ampi distill end to end with a random-weight teacher (tests/fixtures/nets/tiny_depth.ampw):
# one 16-bit label per photo at the photo's size, the manifest, resumption (a photo added
# later is the only one labelled next time), refusals that leave everything as it was,
# and training/train_depth.py taking the folder as --data distilled:LABELS and as
# --teacher-labels LABELS beside an ordinal set.
#   usage: distill_cli.sh AMPI_BINARY SOURCE_DIR
set -u
ampi=$1
src=$2
teacher="$src/tests/fixtures/nets/tiny_depth.ampw"
. "$(dirname "$0")/../support/cli_checks.sh"

# png_header FILE: "width height bit_depth colour_type" from the IHDR chunk.
png_header() {
  od -An -tu1 -j16 -N10 "$1" | awk '{ print $1*16777216 + $2*65536 + $3*256 + $4, $5*16777216 + $6*65536 + $7*256 + $8, $9, $10 }'
}

# Three small photos, one in a subfolder and one a PNG, of sizes no resolution shares.
/usr/bin/python3 - "$tmp/photos" <<'PY'
import sys
from pathlib import Path
import numpy as np
from PIL import Image
root = Path(sys.argv[1])
(root / "sub").mkdir(parents=True)
rng = np.random.default_rng(5)
for name, (w, h) in {"a.jpg": (70, 50), "sub/b.png": (45, 61), "c.jpg": (64, 64)}.items():
    Image.fromarray(rng.integers(0, 256, (h, w, 3), dtype=np.uint8)).save(root / name)
PY
mv "$tmp/photos/c.jpg" "$tmp/later.jpg"

distill() {
  "$ampi" distill --teacher "$teacher" --images "$tmp/photos" -o "$tmp/labels" --threads 2 "$@"
}

distill --resolutions 32,48 >"$tmp/log" 2>&1 || fail "first run: $(cat "$tmp/log")"
[ "$(png_header "$tmp/labels/a.png")" = "70 50 16 0" ] || fail "a.png: header $(png_header "$tmp/labels/a.png")"
[ "$(png_header "$tmp/labels/sub_b.png")" = "45 61 16 0" ] || fail "sub_b.png: header $(png_header "$tmp/labels/sub_b.png")"
grep -q "^resolutions	32,48$" "$tmp/labels/labels.tsv" || fail "labels.tsv lacks the resolutions"
grep -q "^sub_b.png	sub/b.png$" "$tmp/labels/labels.tsv" || fail "labels.tsv lacks sub/b.png"
first=$(md5sum "$tmp/labels/a.png")

# Resuming: only the photo added since is labelled; the others are kept as they were.
mv "$tmp/later.jpg" "$tmp/photos/c.jpg"
distill --resolutions 32,48 >"$tmp/log" 2>&1 || fail "second run: $(cat "$tmp/log")"
grep -q "3 photos labelled (2 by earlier runs)" "$tmp/log" || fail "second run: $(cat "$tmp/log")"
[ "$(grep -c 'ampi distill: \[' "$tmp/log")" = 1 ] || fail "second run labelled more than c.jpg: $(cat "$tmp/log")"
[ "$(md5sum "$tmp/labels/a.png")" = "$first" ] || fail "a.png changed on resuming"

# A Depth Anything V2 teacher runs each square at its own working size.
"$ampi" distill --teacher "$src/tests/fixtures/nets/dav2_tiny.ampw" --images "$tmp/photos" -o "$tmp/dav2" \
  --resolutions 28,42 --threads 2 >"$tmp/log" 2>&1 || fail "dav2 teacher: $(cat "$tmp/log")"
[ "$(png_header "$tmp/dav2/sub_b.png")" = "45 61 16 0" ] || fail "dav2 sub_b.png: header $(png_header "$tmp/dav2/sub_b.png")"
grep -q "^resolutions	28,42$" "$tmp/dav2/labels.tsv" || fail "dav2 labels.tsv lacks the resolutions"

# With the aspect kept the labels are still at each photo's size, and the header says so.
distill --resolutions 32,48 --keep-aspect -o "$tmp/aspect" >"$tmp/log" 2>&1 || fail "--keep-aspect: $(cat "$tmp/log")"
[ "$(png_header "$tmp/aspect/sub_b.png")" = "45 61 16 0" ] || fail "aspect sub_b.png: header $(png_header "$tmp/aspect/sub_b.png")"
grep -q "^resolutions	32,48	aspect kept$" "$tmp/aspect/labels.tsv" || fail "aspect labels.tsv: $(sed -n 3p "$tmp/aspect/labels.tsv")"
cmp -s "$tmp/aspect/a.png" "$tmp/labels/a.png" && fail "--keep-aspect made the squares' label"

# Refusals: one line, non-zero exit, the folder unchanged.
before=$(ls -l "$tmp/labels" | md5sum)
expect_error() {
  text=$1
  shift
  if "$@" >"$tmp/out" 2>"$tmp/err"; then
    fail "'$*' succeeded"
  else
    [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "$text" "$tmp/err" || fail "'$*': stderr '$(cat "$tmp/err")', expected '$text'"
  fi
}
expect_error "this run asks for 'resolutions	32'" distill --resolutions 32
expect_error "this run asks for 'resolutions	32,48	aspect kept'" distill --resolutions 32,48 --keep-aspect
expect_error "'x' is not a side" distill --resolutions 32,x
expect_error "missing --teacher" "$ampi" distill --images "$tmp/photos" -o "$tmp/labels"
mkdir "$tmp/mine" && echo keep >"$tmp/mine/notes.txt"
expect_error "not empty and not made by ampi distill" "$ampi" distill --teacher "$teacher" --images "$tmp/photos" -o "$tmp/mine"
[ "$(cat "$tmp/mine/notes.txt")" = keep ] || fail "the user's folder was touched"
[ "$(ls -l "$tmp/labels" | md5sum)" = "$before" ] || fail "a refused run changed the label folder"

# A linked folder (training/archive_photos.py's photo root) is followed, and its photos keep
# the names they have under --images.
mkdir "$tmp/root" && ln -s "$tmp/photos/sub" "$tmp/root/linked"
"$ampi" distill --teacher "$teacher" --images "$tmp/root/" -o "$tmp/linked_labels" --resolutions 32 --threads 2 \
  >"$tmp/log" 2>&1 || fail "linked folder: $(cat "$tmp/log")"
grep -q "^linked_b.png	linked/b.png$" "$tmp/linked_labels/labels.tsv" \
  || fail "linked folder: labels.tsv $(tail -n +5 "$tmp/linked_labels/labels.tsv")"
[ "$(ls -A "$tmp/linked_labels")" = "$(printf 'labels.tsv\nlinked_b.png')" ] \
  || fail "linked folder: labels $(ls -A "$tmp/linked_labels")"

# The folder trains: two steps of lite on it.
/usr/bin/python3 "$src/training/train_depth.py" --model lite --run "$tmp/run" --data "distilled:$tmp/labels" \
  --size 64x64 --batch 2 --steps 2 --val-every 2 --val-count 1 --workers 0 >"$tmp/train.log" 2>&1 \
  || fail "train_depth.py on the labels: $(tail -5 "$tmp/train.log")"
[ -f "$tmp/run/checkpoint.pt" ] || fail "train_depth.py wrote no checkpoint"

# Or as the ordinal training photos' pseudo ground truth, beside their pairs.
cat >"$tmp/ordinal.json" <<'JSON'
{"photos": [
 {"photo": "a.jpg", "width": 70, "height": 50, "split": "train", "pairs": [{"a": [5, 5], "b": [60, 40], "label": "B"}]},
 {"photo": "sub/b.png", "width": 45, "height": 61, "split": "train", "pairs": [{"a": [5, 50], "b": [40, 5], "label": "A"}]},
 {"photo": "c.jpg", "width": 64, "height": 64, "split": "val", "pairs": [{"a": [3, 60], "b": [60, 3], "label": "A"}]}]}
JSON
AMPI_PHOTO_ROOT="$tmp/photos" /usr/bin/python3 "$src/training/train_depth.py" --model lite --run "$tmp/taught" \
  --data cards --size 64x64 --batch 1 --steps 2 --val-every 2 --val-count 1 --workers 0 --log-every 1 \
  --ordinal "$tmp/ordinal.json" --ordinal-batch 2 --teacher-labels "$tmp/labels" >"$tmp/train.log" 2>&1 \
  || fail "train_depth.py with --teacher-labels: $(tail -5 "$tmp/train.log")"
grep -q "step 2 loss .* rank .* teacher [0-9]" "$tmp/taught/train.log" \
  || fail "no loss on the teacher's labels in the log: $(tail -3 "$tmp/taught/train.log")"

[ "$failures" = 0 ] && echo "distill_cli: all checks passed"
exit "$failures"

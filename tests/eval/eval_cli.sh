#!/bin/sh
# ampi eval depth, slicing and edges through the program, on tiny folders made here.
# A reference written by `ampi depth` with the same network is the network's own
# prediction: eval depth must score it delta = 1 and an RMSE of 16-bit rounding only,
# while the vertical-gradient baseline scores less. Missing and NaN references, bad
# options: non-zero exit, one line on stderr naming the file or option, nothing on stdout.
# A reference of another size: the prediction is resized to it, with a note.
#   usage: eval_cli.sh AMPI_BINARY PHOTO
set -u
ampi=$1
photo=$2
. "$(dirname "$0")/../support/cli_checks.sh"

# expect_error NAME TEXT ARGS...: non-zero exit, nothing on stdout, one stderr line with TEXT.
expect_error() {
  name=$1 text=$2 before=$failures
  shift 2
  "$ampi" eval "$@" >"$tmp/out" 2>"$tmp/err" && fail "$name: exit status 0"
  [ ! -s "$tmp/out" ] || fail "$name: wrote to stdout: $(head -c 200 "$tmp/out")"
  lines=$(wc -l <"$tmp/err")
  [ "$lines" -eq 1 ] || fail "$name: $lines lines on stderr: $(cat "$tmp/err")"
  grep -qF -- "$text" "$tmp/err" || fail "$name: stderr lacks '$text': $(cat "$tmp/err")"
  [ "$failures" -ne "$before" ] || echo "ok: $name -> $(cat "$tmp/err")"
}

# row FILE METHOD: the metrics row of METHOD in eval depth's table.
row() { awk -v m="$2" '$1 == m' "$1"; }

mkdir -p "$tmp/images/sub" "$tmp/ref/sub"
cp "$photo" "$tmp/images/sub/a.jpg"
"$ampi" depth "$tmp/images/sub/a.jpg" -o "$tmp/ref/sub/a.png" --model lite >/dev/null 2>&1 || fail "ampi depth failed"

# The network against its own prediction.
if "$ampi" eval depth --images "$tmp/images" --reference "$tmp/ref" --model lite --threads 2 \
    >"$tmp/out" 2>"$tmp/err"; then
  lite=$(row "$tmp/out" lite)
  gradient=$(row "$tmp/out" vertical-gradient)
  echo "$lite" | awk '{ exit !($2 == 1 && $3 == 1 && $4 == 1 && $5 < 1 && $6 < 0.01 && $7 == 1) }' ||
    fail "lite against its own map: expected delta 1, RMSE < 1 (of 65535): $(cat "$tmp/out")"
  echo "$gradient" | awk '{ exit !($2 < 1 && $5 > 100) }' ||
    fail "vertical-gradient should score below the network's own map: $(cat "$tmp/out")"
  [ "$failures" -eq 0 ] && echo "ok: eval depth, own prediction -> $lite"
else
  fail "eval depth: exit status $?: $(cat "$tmp/err")"
fi

# A reference of another size: a note, and the prediction resized to it.
before=$failures
mkdir -p "$tmp/small/images" "$tmp/small/ref"
cp "$photo" "$tmp/small/images/b.jpg"
/usr/bin/python3 -c "
import numpy as np, sys
y = np.linspace(0, 1, 40, dtype=np.float32)[:, None] * np.ones((1, 64), np.float32)
np.save(sys.argv[1], 1 + y)" "$tmp/small/ref/b.npy"
"$ampi" eval depth --images "$tmp/small/images" --reference "$tmp/small/ref" >"$tmp/out" 2>"$tmp/err" ||
  fail "size mismatch: exit status $?: $(cat "$tmp/err")"
grep -q "is 64x40: the prediction is resized to the reference" "$tmp/err" ||
  fail "size mismatch: no note: $(cat "$tmp/err")"
row "$tmp/out" vertical-gradient | awk '{ exit !($2 == 1) }' ||
  fail "vertical-gradient against a vertical ramp should score delta 1: $(cat "$tmp/out")"
[ "$failures" -ne "$before" ] || echo "ok: size mismatch -> $(grep note "$tmp/err")"

# Errors.
mkdir -p "$tmp/nan/images" "$tmp/nan/ref" "$tmp/missing"
cp "$photo" "$tmp/nan/images/c.jpg"
/usr/bin/python3 -c "
import numpy as np, sys
m = np.ones((40, 64), np.float32); m[3, 5] = np.nan; np.save(sys.argv[1], m)" "$tmp/nan/ref/c.npy"
expect_error "NaN reference" "$tmp/nan/ref/c.npy: contains NaN" depth --images "$tmp/nan/images" --reference "$tmp/nan/ref"
cp "$photo" "$tmp/images/sub/d.jpg"
expect_error "missing reference" "$tmp/images/sub/d.jpg: no reference depth map" \
  depth --images "$tmp/images" --reference "$tmp/ref"
rm "$tmp/images/sub/d.jpg"
expect_error "no reference folder" "$tmp/nope: not a directory" depth --images "$tmp/images" --reference "$tmp/nope"
expect_error "no photos" "no .jpg, .jpeg or .png photos" depth --images "$tmp/missing" --reference "$tmp/ref"
expect_error "bad model" "--model: 'huge'" depth --images "$tmp/images" --reference "$tmp/ref" --model huge
expect_error "bad counts" "--counts: 'x'" slicing --images "$tmp/images" --counts 4,x
expect_error "count out of range" "--counts: '300'" slicing --images "$tmp/images" --counts 300

# An ordinal set on the example photo: pairs whose lower point is labelled nearer, so the
# vertical gradient scores WHDR 0 and a constant map 0.5; the pair labelled "=" is left out.
size=$(/usr/bin/python3 -c "from PIL import Image; import sys; print(*Image.open(sys.argv[1]).size)" "$photo")
w=${size% *} h=${size#* }
cat >"$tmp/ordinal.json" <<JSON
{"photos": [{"photo": "sub/a.jpg", "width": $w, "height": $h, "split": "val", "pairs": [
 {"a": [10, $((h - 10))], "b": [20, 10], "label": "A"},
 {"a": [$((w / 2)), 5], "b": [$((w / 2)), $((h / 2))], "label": "B"},
 {"a": [30, 30], "b": [31, 31], "label": "="}]}]}
JSON
if "$ampi" eval depth --images "$tmp/images" --ordinal "$tmp/ordinal.json" --threads 2 >"$tmp/out" 2>"$tmp/err"; then
  before=$failures
  row "$tmp/out" vertical-gradient | awk '{ exit !($2 == 0 && $3 == 2 && $4 == 1) }' ||
    fail "ordinal: the gradient should order both pairs: $(cat "$tmp/out")"
  row "$tmp/out" constant | awk '{ exit !($2 == 0.5) }' || fail "ordinal: constant should score 0.5: $(cat "$tmp/out")"
  row "$tmp/out" lite | awk '{ exit !($2 >= 0 && $2 <= 1 && $3 == 2) }' || fail "ordinal: no lite row: $(cat "$tmp/out")"
  row "$tmp/out" lite-snapped | awk '{ exit !($2 >= 0 && $2 <= 1 && $3 == 2) }' ||
    fail "ordinal: no row for the snapped map: $(cat "$tmp/out")"
  [ "$failures" -ne "$before" ] || echo "ok: eval depth --ordinal -> $(tr '\n' ' ' <"$tmp/out")"
else
  fail "eval depth --ordinal: exit status $?: $(cat "$tmp/err")"
fi
# The bundled set is gzip-compressed (training/ordinal/ordinal.json.gz): the same set
# compressed must score the same.
gzip -c "$tmp/ordinal.json" >"$tmp/ordinal.json.gz"
if "$ampi" eval depth --images "$tmp/images" --ordinal "$tmp/ordinal.json.gz" --threads 2 >"$tmp/out_gz" 2>"$tmp/err"; then
  cmp -s "$tmp/out" "$tmp/out_gz" && echo "ok: eval depth --ordinal reads a .gz set" ||
    fail "ordinal: the .gz set scored differently: $(cat "$tmp/out_gz")"
else
  fail "eval depth --ordinal, .gz set: exit status $?: $(cat "$tmp/err")"
fi
expect_error "ordinal, empty split" "no photos in split train" \
  depth --images "$tmp/images" --ordinal "$tmp/ordinal.json" --split train
expect_error "ordinal, empty test split" "no photos in split test" \
  depth --images "$tmp/images" --ordinal "$tmp/ordinal.json" --split test
expect_error "ordinal, bad split" "--split: 'held-out'" \
  depth --images "$tmp/images" --ordinal "$tmp/ordinal.json" --split held-out
expect_error "ordinal and reference" "give one of them" \
  depth --images "$tmp/images" --ordinal "$tmp/ordinal.json" --reference "$tmp/ref"
expect_error "ordinal, missing photo" "$tmp/small/images/sub/a.jpg: photo of the ordinal set not found" \
  depth --images "$tmp/small/images" --ordinal "$tmp/ordinal.json"
sed 's/"width": [0-9]*/"width": 2000/' "$tmp/ordinal.json" >"$tmp/ordinal_size.json"
expect_error "ordinal, other size" "but was labelled at 2000x" \
  depth --images "$tmp/images" --ordinal "$tmp/ordinal_size.json"
expect_error "ordinal, missing file" "$tmp/none.json: cannot open" \
  depth --images "$tmp/images" --ordinal "$tmp/none.json"

# Table 3 on one small photo: two rows per count, and the verdict line.
if "$ampi" eval slicing --images "$tmp/images" --counts 2,4 --reference-planes 16 --poses 2 --max-size 128 \
    --threads 2 >"$tmp/out" 2>"$tmp/err"; then
  rows=$(awk '($2 == "uniform" || $2 == "adaptive") && $1 ~ /^[0-9]+$/ && $4 > 0 && $4 <= 1 && $5 > 0' "$tmp/out" | wc -l)
  [ "$rows" -eq 4 ] || fail "eval slicing: $rows valid rows, expected 4: $(cat "$tmp/out")"
  grep -q "^adaptive >= uniform at every count: \(yes\|no\)$" "$tmp/out" || fail "eval slicing: no verdict: $(cat "$tmp/out")"
  [ "$rows" -eq 4 ] && echo "ok: eval slicing -> $(tr '\n' ' ' <"$tmp/out")"
else
  fail "eval slicing: exit status $?: $(cat "$tmp/err")"
fi

# Objects kept whole: one row per scene, softness and pose, before/after columns, the
# target line; and with -o the strips of views.
if "$ampi" eval edges --softness 4 --pose 0.08,0,0 --inpainter push-pull -o "$tmp/edges" \
    --threads 2 >"$tmp/out" 2>"$tmp/err"; then
  rows=$(awk '$2 == "1/4"' "$tmp/out" | wc -l)
  [ "$rows" -eq 4 ] || fail "eval edges: $rows rows, expected 4: $(cat "$tmp/out")"
  grep -q "^poses moving an object 40 px or more: 4;" "$tmp/out" || fail "eval edges: poses not judged"
  grep -q "^target (at most 3% wrong, no fringe): met$" "$tmp/out" || fail "eval edges: target not met"
  [ -f "$tmp/edges/disk_soft4.png" ] || fail "eval edges: no disk_soft4.png in -o"
  [ "$rows" -eq 4 ] && echo "ok: eval edges -> $(tail -2 "$tmp/out" | tr '\n' ' ')"
else
  fail "eval edges: exit status $?: $(cat "$tmp/err")"
fi
expect_error "edges, bad size" "--size: '10x10'" edges --size 10x10
expect_error "edges, bad softness" "--softness: '0'" edges --softness 1,0
expect_error "edges, bad pose" "--pose: '1,2'" edges --pose 1,2
expect_error "edges, missing texture" "$tmp/none.jpg" edges --texture "$tmp/none.jpg"
expect_error "edges, photos without -o" "--images needs -o DIR" edges --images "$tmp/images"
if "$ampi" eval edges --images "$tmp/images" -o "$tmp/sheets" --max-size 128 --pose 0.05,0,0 >"$tmp/out" 2>"$tmp/err"; then
  sheets=$(find "$tmp/sheets" -name '*.png' | wc -l)
  [ "$sheets" -ge 1 ] || fail "eval edges --images: no sheet written"
  grep -q "planes before" "$tmp/out" || fail "eval edges --images: no line per photo"
  [ "$sheets" -ge 1 ] && echo "ok: eval edges --images -> $sheets sheet(s)"
else
  fail "eval edges --images: exit status $?: $(cat "$tmp/err")"
fi

[ "$failures" -eq 0 ] || { echo "$failures failure(s)" >&2; exit 1; }
echo "all eval CLI checks passed"

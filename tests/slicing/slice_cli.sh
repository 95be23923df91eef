#!/bin/sh
# ampi slice on a depth map with three flat levels: three planes by default and with
# either slicer, at most two with --max-planes 2, at most four uniform ones; bad input exits non-zero with one line
# on stderr naming the file.
#   usage: slice_cli.sh AMPI_BINARY THREE_LEVEL_PNG
set -u
ampi=$1
depth=$2
. "$(dirname "$0")/../support/cli_checks.sh"

# planes NAME MIN MAX ARGS...: exit 0 and between MIN and MAX planes printed.
planes() {
  name=$1 min=$2 max=$3 before=$failures
  shift 3
  "$ampi" slice "$@" >"$tmp/out" 2>"$tmp/err" || fail "$name: exit status $?: $(cat "$tmp/err")"
  n=$(grep -o '"depth"' "$tmp/out" | wc -l)
  { [ "$n" -ge "$min" ] && [ "$n" -le "$max" ]; } || fail "$name: $n planes, expected $min..$max: $(cat "$tmp/out")"
  grep -q '^{"planes": \[' "$tmp/out" || fail "$name: output is not the planes JSON: $(cat "$tmp/out")"
  [ "$failures" -ne "$before" ] || echo "ok: $name -> $n planes"
}

# expect_error NAME TEXT ARGS...: non-zero exit, nothing on stdout, one stderr line with TEXT.
expect_error() {
  name=$1 text=$2 before=$failures
  shift 2
  "$ampi" slice "$@" >"$tmp/out" 2>"$tmp/err" && fail "$name: exit status 0"
  [ ! -s "$tmp/out" ] || fail "$name: wrote to stdout: $(head -c 200 "$tmp/out")"
  lines=$(wc -l <"$tmp/err")
  [ "$lines" -eq 1 ] || fail "$name: $lines lines on stderr: $(cat "$tmp/err")"
  grep -qF -- "$text" "$tmp/err" || fail "$name: stderr lacks '$text': $(cat "$tmp/err")"
  [ "$failures" -ne "$before" ] || echo "ok: $name -> $(cat "$tmp/err")"
}

planes "three levels" 3 3 "$depth"
planes "max planes 2" 1 2 "$depth" --max-planes 2
planes "uniform 4" 1 4 "$depth" --uniform --max-planes 4
planes "as distances" 3 3 "$depth" --depth-is-distance
planes "paper slicer" 3 3 "$depth" --slicer paper
planes "tear penalty" 3 3 "$depth" --tear-penalty 100
"$ampi" slice --help >"$tmp/out" || fail "--help: exit status $?"
grep -q "usage: ampi slice" "$tmp/out" || fail "--help: no usage text"

printf 'not an image' >"$tmp/text.png"
expect_error missing "$tmp/missing.png: no such file" "$tmp/missing.png"
expect_error unreadable "$tmp/text.png: not a readable image" "$tmp/text.png"
expect_error "bad max planes" "--max-planes" "$depth" --max-planes 0
expect_error "unknown option" "unknown option '--planes'" "$depth" --planes 3
expect_error "bad slicer" "--slicer: 'greedy' is not paper or optimal" "$depth" --slicer greedy
expect_error "bad share" "--min-plane-share: '2' is not a number in 0..1" "$depth" --min-plane-share 2
expect_error "bad tear penalty" "--tear-penalty: '-1' is not a number in 0..1e+09" "$depth" --tear-penalty -1

[ "$failures" -eq 0 ]

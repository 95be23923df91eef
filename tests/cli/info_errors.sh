#!/bin/sh
# ampi info on damaged copies of a weight file: each must exit non-zero with exactly one
# line on stderr and nothing on stdout; the undamaged file must exit 0.
#   usage: info_errors.sh AMPI_BINARY WEIGHT_FILE
set -u
ampi=$1
good=$2
. "$(dirname "$0")/../support/cli_checks.sh"

# expect_error NAME FILE TEXT: non-zero exit, one stderr line naming FILE and containing TEXT.
expect_error() {
  before=$failures
  "$ampi" info "$2" >"$tmp/out" 2>"$tmp/err"
  status=$?
  [ "$status" -ne 0 ] || fail "$1: exit status 0"
  [ ! -s "$tmp/out" ] || fail "$1: wrote to stdout: $(head -c 200 "$tmp/out")"
  lines=$(wc -l <"$tmp/err")
  [ "$lines" -eq 1 ] || fail "$1: $lines lines on stderr: $(cat "$tmp/err")"
  grep -qF "$2: $3" "$tmp/err" || fail "$1: stderr lacks '$2: $3': $(cat "$tmp/err")"
  [ "$failures" -ne "$before" ] || echo "ok: $1 -> $(cat "$tmp/err")"
}

size=$(wc -c <"$good")
head -c $((size / 2)) "$good" >"$tmp/truncated.ampw"
: >"$tmp/empty.ampw"
{ printf 'XMPW'; tail -c +5 "$good"; } >"$tmp/bad_magic.ampw"

expect_error truncated "$tmp/truncated.ampw" "truncated"
expect_error empty "$tmp/empty.ampw" "empty file"
expect_error "bad magic" "$tmp/bad_magic.ampw" "bad magic"
expect_error missing "$tmp/missing.ampw" "cannot open"

"$ampi" info "$good" >"$tmp/out" 2>"$tmp/err" || fail "good file: exit status $?: $(cat "$tmp/err")"
[ ! -s "$tmp/err" ] || fail "good file: wrote to stderr: $(cat "$tmp/err")"
grep -q "^total: " "$tmp/out" || fail "good file: no totals line in: $(cat "$tmp/out")"
"$ampi" info --help >/dev/null || fail "--help: exit status $?"

[ "$failures" -eq 0 ] || exit 1
echo "all ampi info checks passed"

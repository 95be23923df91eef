#!/bin/sh
# ampi bench pipeline on a tiny photo size: every stage's row carries its time and its
# own peak resident memory, the whole run's peak is given, and so is the video encoder's
# when the ffmpeg program encodes the MP4 in a process of its own. A bad --sizes is one
# line naming the problem.
#   usage: bench_pipeline_cli.sh AMPI_BINARY PHOTO
set -u
ampi=$1
photo=$2
. "$(dirname "$0")/../support/cli_checks.sh"

"$ampi" bench pipeline --photo "$photo" --sizes 96x64 --runs 1 --frames 3 --inpainter push-pull \
  --out "$tmp/table.md" >"$tmp/stdout" 2>"$tmp/err" || fail "exit $?: $(cat "$tmp/err")"
cmp -s "$tmp/stdout" "$tmp/table.md" || fail "the table printed differs from the one written"
grep -qF '| stage | 96x64 (ms) | peak (MB) |' "$tmp/table.md" || fail "no header with a peak column: $(cat "$tmp/table.md")"

# A stage's row: | NAME | MS | MB | with a positive peak.
for stage in decode depth slicing assembly inpainting "write mpi" "render+encode"; do
  row=$(grep -F "| $stage |" "$tmp/table.md" | head -1)
  [ -n "$row" ] || { fail "no row for $stage"; continue; }
  peak=$(echo "$row" | awk -F'|' '{gsub(/ /, "", $4); print $4}')
  case $peak in
    '' | *[!0-9]*) fail "$stage: peak '$peak' is not a number of MB: $row" ;;
    *) [ "$peak" -gt 0 ] || fail "$stage: peak 0 MB: $row" ;;
  esac
done

# A table-wide row's number, the last cell's digits: | NAME | | **MB** |
last_number() {
  grep -F "$1" "$tmp/table.md" | head -1 | awk -F'|' '{v = $(NF - 1); gsub(/[ *]/, "", v); print v}'
}
whole=$(last_number '| **whole run** (peak of any stage) |')
[ "${whole:-0}" -gt 0 ] 2>/dev/null || fail "whole run peak '$whole'"
encoder=$(last_number '| video encoder, its own process (ffmpeg) |')
case $encoder in
  '' | *[!0-9]*) fail "encoder peak '$encoder' is not a number of MB" ;;
esac
if command -v ffmpeg >/dev/null 2>&1; then
  [ "${encoder:-0}" -gt 0 ] 2>/dev/null || fail "ffmpeg is installed but the encoder's peak is '$encoder'"
fi
with=$(last_number '| **whole run with the encoder**')
[ "${with:-0}" -ge "${whole:-0}" ] 2>/dev/null || fail "whole run with the encoder '$with' below the run's '$whole'"

"$ampi" bench pipeline --sizes 96 --out "$tmp/never.md" >/dev/null 2>"$tmp/err" && fail "bad --sizes: exit 0"
[ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "bad --sizes: not one line: $(cat "$tmp/err")"
grep -qF "'96' is not a size WxH" "$tmp/err" || fail "bad --sizes: $(cat "$tmp/err")"
[ ! -e "$tmp/never.md" ] || fail "bad --sizes wrote a table"

[ "$failures" -eq 0 ] && echo "ok: bench pipeline reports every stage's peak (whole run $whole MB, encoder $encoder MB)"
exit "$failures"

#!/bin/sh
# ampi render end to end on a small MPI folder (tests/render/fixture_mpi: 64x48, 3 soft
# layers, test::synthetic_mpi(64, 48, 3, 7, Alpha::Soft) saved by write_mpi).
# usage: render_cli.sh AMPI MPI_DIR
set -u
ampi=$1
mpi=$2
. "$(dirname "$0")/../support/cli_checks.sh"

# expect_error NEEDLE ARGS...: the command fails with one line on stderr containing NEEDLE.
expect_error() {
  needle=$1
  shift
  if "$ampi" render "$@" > /dev/null 2> "$tmp/err.txt"; then
    fail "accepted: $*"
    return
  fi
  grep -qF -- "$needle" "$tmp/err.txt" || fail "'$*' did not say '$needle': $(cat "$tmp/err.txt")"
  [ "$(wc -l < "$tmp/err.txt")" -eq 1 ] || fail "'$*' wrote more than one line: $(cat "$tmp/err.txt")"
}

count_files() { find "$1" -type f | wc -l; }

# One frame, refused the second time, replaced with --force.
"$ampi" render "$mpi" --pose 0.05,-0.02,0 -o "$tmp/frame.png" > /dev/null || fail "--pose"
[ -s "$tmp/frame.png" ] || fail "--pose wrote no frame.png"
expect_error "frame.png: already exists" "$mpi" --pose 0,0,0 -o "$tmp/frame.png"
"$ampi" render "$mpi" --pose 0,0,0 -o "$tmp/frame.png" --force > /dev/null || fail "--force"

# Videos, frame folders, stereo, keyframes, the viewer.
"$ampi" render "$mpi" -o "$tmp/clip.mp4" --frames 6 --fps 12 > /dev/null || fail "mp4"
[ -s "$tmp/clip.mp4" ] || fail "no clip.mp4"
"$ampi" render "$mpi" -o "$tmp/seq" --trajectory zoom-in --frames 5 --one-way > /dev/null || fail "png sequence"
[ "$(count_files "$tmp/seq")" -eq 5 ] || fail "zoom-in --frames 5 wrote $(count_files "$tmp/seq") frames"
"$ampi" render "$mpi" -o "$tmp/dolly" --trajectory dolly-zoom --frames 4 --amplitude 0.2 > /dev/null || fail "dolly-zoom"
"$ampi" render "$mpi" -o "$tmp/sbs" --format sbs --frames 3 > /dev/null || fail "sbs"
[ "$(count_files "$tmp/sbs")" -eq 3 ] || fail "sbs wrote $(count_files "$tmp/sbs") frames"
"$ampi" render "$mpi" -o "$tmp/red-cyan.png" --format anaglyph --pose 0,0,0 > /dev/null || fail "anaglyph"
printf '{"keyframes": [{"time": 0}, {"time": 0.5, "t": [0.1, 0, 0]}]}' > "$tmp/keys.json"
"$ampi" render "$mpi" -o "$tmp/keys" --keyframes "$tmp/keys.json" --fps 10 > /dev/null || fail "keyframes"
[ "$(count_files "$tmp/keys")" -eq 6 ] || fail "0.5 s at 10 fps gave $(count_files "$tmp/keys") frames, not 6"
"$ampi" render "$mpi" -o "$tmp/view.html" > /dev/null || fail "viewer"
grep -q "data:image/png;base64," "$tmp/view.html" || fail "viewer without embedded layers"
if command -v ffmpeg > /dev/null; then
  "$ampi" render "$mpi" -o "$tmp/loop.gif" --trajectory swing --frames 4 > /dev/null || fail "gif"
  [ -s "$tmp/loop.gif" ] || fail "no loop.gif"
fi

# Mistakes: one line naming the file or the option, and nothing left behind.
before=$(ls -A "$tmp" | sort | tr '\n' ' ')
expect_error "$tmp/missing: " "$tmp/missing" --pose 0,0,0 -o "$tmp/x.png"
printf '{"keyframes": [{"time": 1}, {"time": 0}]}' > "$tmp/bad.json"
expect_error "bad.json: keyframe 1" "$mpi" -o "$tmp/y.mp4" --keyframes "$tmp/bad.json"
rm "$tmp/bad.json"
expect_error "--pose: 'a,b' is not three numbers" "$mpi" --pose a,b -o "$tmp/x.png"
expect_error "x.png: a .png holds one frame" "$mpi" -o "$tmp/x.png"
expect_error "x.mp4: --pose writes one frame" "$mpi" --pose 0,0,0 -o "$tmp/x.mp4"
expect_error "--format: 'webm'" "$mpi" -o "$tmp/x.mp4" --format webm
expect_error "x.mp4: does not suit --format gif" "$mpi" -o "$tmp/x.mp4" --format gif
expect_error "exclude each other" "$mpi" -o "$tmp/x.mp4" --boomerang --one-way
expect_error "exclude each other" "$mpi" -o "$tmp/x.png" --pose 0,0,0 --trajectory swing
expect_error "unknown trajectory 'spin'" "$mpi" -o "$tmp/x.mp4" --trajectory spin
expect_error "--amplitude" "$mpi" -o "$tmp/x.mp4" --amplitude 2
expect_error "nowhere/x.mp4: directory" "$mpi" -o "$tmp/nowhere/x.mp4"
expect_error "focus plane 7 does not exist" "$mpi" -o "$tmp/x.mp4" --trajectory dolly-zoom --focus-plane 7
after=$(ls -A "$tmp" | sort | tr '\n' ' ')
[ "$before" = "$after" ] || fail "failed runs left files: before '$before', after '$after'"

"$ampi" render --help | grep -q "usage: ampi render" || fail "--help"
[ "$failures" -eq 0 ] && echo "render_cli: all checks passed"
exit "$failures"

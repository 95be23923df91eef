#!/usr/bin/env bash
# Reliability checks (RELIABILITY.md says what each found):
#   1. AddressSanitizer + UndefinedBehaviorSanitizer build (build-asan/): the unit tests;
#   2. the memory budget and allocation failures through that build's ampi program;
#   3. ThreadSanitizer build (build-tsan/): the threaded engine, kernel and renderer tests;
#   4. libFuzzer build (build-fuzz/, Debian's clang): every parser of outside data, each
#      fuzzed for AMPI_FUZZ_SECONDS (default 20) from its seed corpus in fuzz/corpus/,
#      which also holds every input that once crashed a target (replayed first).
# Exits non-zero on any failing test, sanitizer report or fuzz finding; a finding's input
# is kept in build-fuzz/artifacts/. AMPI_RELIABILITY_ONLY=asan|memory|tsan|fuzz runs one part
# (memory needs the asan part's build).
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=$(nproc)
fuzz_seconds=${AMPI_FUZZ_SECONDS:-20}
only=${AMPI_RELIABILITY_ONLY:-}
fuzz_targets=(weight_file networks npy mpi_json depth_map photo keyframes)
# -O1: the sanitizers' usual level (fast enough, readable reports); -g1: source lines.
# GCC's -Wmaybe-uninitialized misfires on sanitizer-instrumented code (in libstdc++'s
# <regex> here), so the sanitizer builds leave it out.
sanitizer_build_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -Wno-maybe-uninitialized")

run_asan() {
  echo "== ASan + UBSan: unit tests"
  cmake -S . -B build-asan -DAMPI_SANITIZE=ON "${sanitizer_build_flags[@]}" >/dev/null
  cmake --build build-asan -j"$jobs"
  # The Python tests never load ampi's C++ and gain nothing from the sanitizers.
  ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure --no-tests=error -E 'python|^training' -j"$jobs"
}

run_tsan() {
  echo "== TSan: engine, kernels, render tests"
  cmake -S . -B build-tsan "${sanitizer_build_flags[@]}" \
    -DCMAKE_CXX_FLAGS=-fsanitize=thread -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread >/dev/null
  cmake --build build-tsan -j"$jobs" --target test_engine test_kernels test_render
  # The video tests reach FFmpeg's frame threads (and GDAL's locks, through OpenCV):
  # libraries built without TSan, whose synchronisation it cannot see. Their reports are
  # about them, not ampi; ampi's own code stays fully checked.
  cat >build-tsan/tsan.supp <<'SUPPRESSIONS'
race:libavcodec.so
race:libavutil.so
race:libavformat.so
race:libswscale.so
deadlock:libgdal.so
SUPPRESSIONS
  # The tests' full shapes: small ones may fit in one thread pool chunk and race nothing.
  TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/build-tsan/tsan.supp \
    ctest --test-dir build-tsan --output-on-failure --no-tests=error -R '^(engine|kernels|render)$' -j"$jobs"
}

# Runs "$@", which must fail with exit code 1 and one line on stderr containing
# `expected`, and must not leave `output` behind.
expect_refusal() {
  local expected=$1 output=$2 status=0
  shift 2
  "$@" 2>"$scratch/stderr.raw" >/dev/null || status=$?
  # ASan's own notice of an allocation it refused is not ampi's output.
  grep -v 'WARNING: AddressSanitizer failed to allocate' "$scratch/stderr.raw" >"$scratch/stderr" || true
  if [ $status -ne 1 ] || [ "$(wc -l <"$scratch/stderr")" -ne 1 ] || ! grep -qF "$expected" "$scratch/stderr" ||
     [ -e "$output" ] || [ -e "$output.tmp" ]; then
    echo "expected exit 1, one line with '$expected' and no $output; got exit $status:"
    cat "$scratch/stderr"
    return 1
  fi
  echo "ok: $(cat "$scratch/stderr")"
}

run_memory() {
  echo "== memory: the budget and allocation failures, through the ASan build's ampi"
  cmake --build build-asan -j"$jobs" --target ampi
  scratch=$(mktemp -d)
  trap 'rm -rf "$scratch"' EXIT
  /usr/bin/python3 -c "from PIL import Image; Image.new('RGB', (6000, 4000), (90, 120, 60)).save('$scratch/big.jpg')"
  local depth=(build-asan/ampi depth "$scratch/big.jpg" -o "$scratch/depth.png" --max-size 6000)
  # Over the budget: refused before the network allocates anything.
  AMPI_MEMORY_BUDGET=256M expect_refusal "over the 256.0 MiB memory budget" "$scratch/depth.png" "${depth[@]}"
  # A whole run: the layers are checked before any work, and no output folder appears.
  AMPI_MEMORY_BUDGET=16M expect_refusal "needs 20.0 MiB for 8 RGBA layers at 1024x640" "$scratch/run" \
    build-asan/ampi run examples/forest_path.jpg -o "$scratch/run" --quiet
  # Within a generous budget but more than the allocator gives: std::bad_alloc from the
  # arena (ASan makes the allocation fail: allocator_may_return_null with a size cap),
  # reported as one line, not a crash.
  AMPI_MEMORY_BUDGET=1T ASAN_OPTIONS=allocator_may_return_null=1:max_allocation_size_mb=1024 \
    expect_refusal "out of memory" "$scratch/depth.png" "${depth[@]}"
}

# Prints "target executions" and returns libFuzzer's status.
fuzz_one() {
  local target=$1 work=build-fuzz/corpus/$1 log=build-fuzz/logs/$1.log
  mkdir -p "$work" build-fuzz/artifacts build-fuzz/logs
  # New inputs go to the first folder (build-fuzz/); the committed seeds stay as they are.
  local status=0 options=()
  case $target in mpi_json | keyframes) options+=(-dict=fuzz/json.dict) ;; esac
  build-fuzz/fuzz_"$target" "${options[@]}" -max_total_time="$fuzz_seconds" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix=build-fuzz/artifacts/"$target"- \
    "$work" fuzz/corpus/"$target" >"$log" 2>&1 || status=$?
  local runs
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  printf '%-12s %10s executions  %s\n' "$target" "${runs:-?}" "$([ $status -eq 0 ] && echo ok || echo FAILED)"
  [ $status -eq 0 ] || { tail -n 40 "$log"; return $status; }
}

run_fuzz() {
  echo "== libFuzzer: ${#fuzz_targets[@]} targets, ${fuzz_seconds} s each"
  cmake -S fuzz -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ >/dev/null
  cmake --build build-fuzz -j"$jobs" --target "${fuzz_targets[@]/#/fuzz_}"
  # OpenCV's own decoder limit, for the formats whose headers ampi does not read before
  # decoding (TIFF, BMP, ...): 16 Mpixels keeps a lying header under libFuzzer's RSS
  # limit. PNG and JPEG headers meet ampi's memory budget before OpenCV sees them.
  export OPENCV_IO_MAX_IMAGE_PIXELS=16777216
  export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  local failed=0
  for target in "${fuzz_targets[@]}"; do fuzz_one "$target" || failed=1; done
  return $failed
}

start=$SECONDS
for part in asan memory tsan fuzz; do
  if [ -z "$only" ] || [ "$only" = "$part" ]; then "run_$part"; fi
done
echo "== reliability checks passed in $((SECONDS - start)) s"

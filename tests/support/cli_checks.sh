# Sourced by the command-line tests (tests/*/*.sh, run by ctest): a temporary folder
# removed on exit ($tmp), and fail, which reports a check on stderr and counts it
# ($failures), so that a script runs every check before it exits with the count.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

#!/usr/bin/env bash
# Builds PSQ under a sanitizer (PSQ_SANITIZE, docs/sanitizers.md) and runs tests under it:
#   scripts/sanitize.sh address   ASan + UBSan into build-asan, the whole suite
#   scripts/sanitize.sh thread    TSan into build-tsan, the tests that run threads
# Any sanitizer report fails the script, also one from a psq child process whose exit code a
# test expects to be non-zero: reports go to files (log_path), and any file is a failure.
#
# RelWithDebInfo (-O2 -g1, assertions on), not -O1 -g: it is how scripts/test.sh builds the
# suite, so the sanitizers check the code as it is tested, and the numerical tests, which the
# sanitizers slow several times over, keep within ctest's 900 s timeout. -g1 keeps the line
# tables the reports need; -fno-omit-frame-pointer (CMakeLists.txt) keeps their stacks whole.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-address}
case "$mode" in
  address) build_dir=build-asan ;;
  thread) build_dir=build-tsan ;;
  *)
    echo "usage: scripts/sanitize.sh [address|thread]" >&2
    exit 2
    ;;
esac
./scripts/build.sh "$build_dir" RelWithDebInfo -DPSQ_SANITIZE="$mode"

reports="$PWD/$build_dir/sanitizer-reports"
rm -rf "$reports"
mkdir -p "$reports"
# exitcode=86: a report must not pass for psq's exit code 1 (bad input) that tests expect.
common="halt_on_error=1:print_stacktrace=1:exitcode=86:log_path=$reports/report"
export ASAN_OPTIONS="$common:detect_leaks=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="$common"
export TSAN_OPTIONS="$common:second_deadlock_stack=1:suppressions=$PWD/tests/tsan.supp"

ctest_run() { ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)" --timeout 900 "$@"; }
status=0
if [ "$mode" = address ]; then
  # The Slurm tests need the localhost cluster; it is stopped at the end only if this script
  # started it, so that a cluster another run relies on keeps running.
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  if ! $SUDO ./scripts/slurm-localhost.sh status | grep -q "slurmd running"; then
    trap '$SUDO ./scripts/slurm-localhost.sh stop' EXIT
    $SUDO ./scripts/slurm-localhost.sh start ||
      echo "sanitize.sh: the localhost SLURM cluster did not start; the Slurm tests will fail" >&2
  fi
  # Excluded: it timed out at ctest's 900 s under ASan on 2 shared cores (docs/sanitizers.md).
  ctest_run -E '^ProgressiveContact\.TwistWithSelfContactIsIntersectionFreeAtEveryLevelAndConverges$' ||
    status=$?
else
  # The modules whose code runs TBB loops (elastic, contact, hierarchy, progressive) or threads
  # of its own (the solver's OpenMP and OpenBLAS settings, the job executor's heartbeat), the
  # store's worker processes (db), and psq work with several workers (runner). With Debian's
  # uninstrumented libtbb the TBB loops report false positives that cannot be suppressed
  # without hiding PSQ code (docs/sanitizers.md), so this run fails until TBB is built with TSan.
  ctest_run -L '^(elastic|contact|hierarchy|progressive|solver|jobs|db)$' || status=$?
  ctest_run -R '^(WorkCommand|KillCommand|ResumeCommand)\.' || status=$?
fi

if [ -n "$(ls -A "$reports")" ]; then
  for report in "$reports"/*; do
    echo "=== $report" >&2
    cat "$report" >&2
  done
  echo "sanitize.sh: sanitizer reports above (in $reports)" >&2
  exit 1
fi
exit "$status"

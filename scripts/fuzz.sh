#!/usr/bin/env bash
# Builds the libFuzzer targets (PSQ_FUZZ, clang) into build-fuzz and runs each for a short
# while: FUZZ_SECONDS per target (default 25), or FUZZ_RUNS executions per target when that is
# set (docs/fuzzing.md: the long run). Any crash, sanitizer report, non-InputError
# exception, hang (> 10 s on one input) or memory blow-up fails the script, and libFuzzer
# leaves the input as crash-*/timeout-*/oom-* in build-fuzz/findings. docs/fuzzing.md has
# the long runs.
set -euo pipefail
cd "$(dirname "$0")/.."
limit=(-max_total_time="${FUZZ_SECONDS:-25}")
[ -z "${FUZZ_RUNS:-}" ] || limit=(-runs="$FUZZ_RUNS")
cmake -S . -B build-fuzz -DPSQ_FUZZ=ON -DPSQ_BUILD_TESTS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ >/dev/null
targets=(obj off ply scene sweep)
cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]/#/fuzz_}"

# Seeds: the hand-written meshes and sweeps of tests/fuzz/corpus and the library's scenes,
# sweeps and meshes.
# New inputs go into build-fuzz/corpus/<target>, the first (writable) corpus directory.
declare -A seeds=(
  [obj]="tests/fuzz/corpus/obj jobs/data"
  [off]="tests/fuzz/corpus/off"
  [ply]="tests/fuzz/corpus/ply"
  [scene]="jobs/scenes"
  [sweep]="tests/fuzz/corpus/sweep jobs/sweeps"
)
mkdir -p build-fuzz/findings
for target in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$target"
  log="build-fuzz/fuzz_$target.log"
  # shellcheck disable=SC2086 # seeds[] holds a list of directories
  if ! build-fuzz/tests/fuzz/fuzz_"$target" "build-fuzz/corpus/$target" ${seeds[$target]} \
    "${limit[@]}" -seed=1 -timeout=10 -max_len=4096 -print_final_stats=1 \
    -artifact_prefix=build-fuzz/findings/"$target"- >"$log" 2>&1; then
    tail -n 40 "$log" >&2
    echo "fuzz.sh: fuzz_$target found a problem; its input is in build-fuzz/findings" >&2
    exit 1
  fi
  echo "fuzz_$target: $(grep -E '^Done' "$log"), $(grep -E 'average_exec_per_sec' "$log" | tr -s ' ')"
done

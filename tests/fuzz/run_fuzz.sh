#!/usr/bin/env bash
# Builds the fuzz target with clang (ASan + UBSan + libFuzzer) and runs it for the given seconds over a copy of the
# seed corpus, then prints what libFuzzer reports: the executions and the coverage it reached.
#   bash tests/fuzz/run_fuzz.sh [seconds]        (default 60)
#   QUATHINGE_FUZZ_DIR=/tmp/f bash tests/fuzz/run_fuzz.sh 120    build directory other than build-fuzz/
#   QUATHINGE_FUZZ_PRECISION=double …                              against Debian's double-precision Bullet
# A finding stops the run, is saved as <build dir>/crashes/crash-<sha1> (reproduce: <build dir>/tests/fuzz/
# quathinge_fuzz <file>; minimize: add -minimize_crash=1 -runs=10000) and makes the script fail. A reproducer of a
# real bug goes into tests/fuzz/crashes/ with a note in tests/fuzz/FINDINGS.md, and into the corpus once fixed.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-60}
dir=${QUATHINGE_FUZZ_DIR:-build-fuzz}
double=OFF
if [ "${QUATHINGE_FUZZ_PRECISION:-float}" = double ]; then double=ON; fi
command -v clang++ >/dev/null || { echo "run_fuzz: clang++ missing (bash cmake/setup-debian.sh installs it)" >&2; exit 1; }

CC=clang CXX=clang++ cmake -S . -B "$dir" -DQUATHINGE_FUZZ=ON -DQUATHINGE_BUILD_DEMOS=OFF \
  -DQUATHINGE_DOUBLE_PRECISION=$double -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$dir" -j2 --target quathinge_fuzz
rm -rf "$dir/corpus" && cp -r tests/fuzz/corpus "$dir/corpus"
mkdir -p "$dir/crashes"
set +e
# QUATHINGE_FUZZ_SEED fixes libFuzzer's random seed (CI: 1); unset, libFuzzer picks one and prints it. A fixed seed
# does not make a timed run repeat itself: the number of inputs tried depends on the machine's speed, and the coverage
# libFuzzer steers by varies from run to run (Bullet's profiler reads the clock). So a finding is printed whole below,
# to be replayed from the log of the machine that found it.
seed=()
if [ -n "${QUATHINGE_FUZZ_SEED:-}" ]; then seed=(-seed="$QUATHINGE_FUZZ_SEED"); fi
"$dir/tests/fuzz/quathinge_fuzz" "${seed[@]}" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$dir/crashes/" "$dir/corpus" >"$dir/fuzz.log" 2>&1
status=$?
set -e
# "#<n> INITED/DONE cov: <edges> ft: <features> corp: <units>/<bytes> exec/s: <rate> rss: <memory>" and the totals.
grep -E "^#[0-9]+[[:space:]]+(INITED|DONE)|^stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)" \
  "$dir/fuzz.log" || true
if [ $status -ne 0 ]; then
  echo "run_fuzz: the fuzzer stopped with status $status; the report (end of $dir/fuzz.log):" >&2
  grep -E "quathinge_fuzz:|ERROR|SUMMARY|runtime error|Test unit written|artifact" "$dir/fuzz.log" | head -20 >&2
  # The input itself (base64; save it with `base64 -d > crash`) and its replay with the scene printed, so a finding
  # on another machine can be reproduced here.
  for unit in "$dir"/crashes/*; do
    [ -f "$unit" ] || continue
    echo "run_fuzz: input $(basename "$unit"), base64:" >&2
    base64 -w 0 "$unit" >&2 && echo >&2
    echo "run_fuzz: its replay with QUATHINGE_FUZZ_VERBOSE=1 (last 80 lines):" >&2
    QUATHINGE_FUZZ_VERBOSE=1 "$dir/tests/fuzz/quathinge_fuzz" "$unit" 2>&1 | tail -80 >&2 || true
  done
  exit $status
fi

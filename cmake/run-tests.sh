#!/usr/bin/env bash
# README's test command: set up, build both Bullet precisions, run every test. CI runs the same, then --asan-only.
#   bash cmake/run-tests.sh                    float and double builds (build/, build-double/)
#   bash cmake/run-tests.sh --asan             also the AddressSanitizer + UBSan Debug build at -O1, Clang (build-asan/)
#   bash cmake/run-tests.sh --asan-only        only the sanitizer build
#   bash cmake/run-tests.sh DIR [CMAKE_ARGS…]  one build: configure DIR with the extra arguments, build, ctest
set -euo pipefail
cd "$(dirname "$0")/.."

build_and_test() {
  local dir=$1; shift
  echo "=== $dir $*"
  cmake -S . -B "$dir" -DQUATHINGE_WERROR=ON "$@" >/dev/null   # errors and warnings still reach stderr
  cmake --build "$dir" -j2
  # ctest starts the tests it knows to be long first (their times from the last run, Testing/Temporary/
  # CTestCostData.txt): a new build has none, so it is given tests/ctest-costs.txt, the longest ones' times in the
  # sanitizer build (s; the crowd of ragdolls, which that build skips, takes half a minute in the others), or the longest
  # may start last, one core idle meanwhile (CI's sanitizer stage: ~2 min).
  if [ ! -f "$dir/Testing/Temporary/CTestCostData.txt" ]; then
    mkdir -p "$dir/Testing/Temporary"
    cp tests/ctest-costs.txt "$dir/Testing/Temporary/CTestCostData.txt"
  fi
  ctest --test-dir "$dir" --output-on-failure -j2
}
# Clang: its sanitized build of the tests takes about 0.55 times GCC's CPU (the heaviest test file 3.6 s against 6.6 s
# at -O1 -g1), and its ASan and UBSan are the same runtimes' checks.
asan() { build_and_test build-asan -DQUATHINGE_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER=clang++; }

case "${1:-}" in
  -* ) [[ "$1" == --asan || "$1" == --asan-only ]] ||
       { echo "usage: $0 [--asan | --asan-only | DIR [CMAKE_ARGS...]]" >&2; exit 2; } ;;
esac
bash cmake/setup-debian.sh --quick
case "${1:-}" in
  "" | --asan)
    build_and_test build
    build_and_test build-double -DQUATHINGE_DOUBLE_PRECISION=ON
    if [ "${1:-}" = --asan ]; then asan; fi ;;
  --asan-only) asan ;;
  *) build_and_test "$@" ;;
esac

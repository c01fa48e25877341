#!/usr/bin/env bash
# README's test command: set up, build both Bullet precisions, run every test.
#   bash cmake/run-tests.sh            float and double builds (build/, build-double/)
#   bash cmake/run-tests.sh --asan     also an AddressSanitizer + UBSan build (build-asan/)
set -euo pipefail
cd "$(dirname "$0")/.."
bash cmake/setup-debian.sh

asan=0
for arg in "$@"; do
  case "$arg" in
    --asan) asan=1 ;;
    *) echo "usage: $0 [--asan]" >&2; exit 2 ;;
  esac
done

build_and_test() {
  local dir=$1; shift
  echo "=== $dir $*"
  cmake -S . -B "$dir" -DQUATHINGE_WERROR=ON "$@" >/dev/null
  cmake --build "$dir" -j2
  ctest --test-dir "$dir" --output-on-failure -j2
}

build_and_test build
build_and_test build-double -DQUATHINGE_DOUBLE_PRECISION=ON
if [ "$asan" -eq 1 ]; then
  build_and_test build-asan -DQUATHINGE_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DQUATHINGE_BUILD_DEMOS=ON
fi

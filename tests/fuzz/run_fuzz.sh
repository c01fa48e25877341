#!/usr/bin/env bash
# Builds the fuzz target with clang in build-fuzz/ and runs it for the given seconds over a copy of the seed corpus.
#   bash tests/fuzz/run_fuzz.sh [seconds]
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-60}
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DQUATHINGE_FUZZ=ON -DQUATHINGE_BUILD_DEMOS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build-fuzz -j2 --target quathinge_fuzz
rm -rf build-fuzz/corpus && cp -r tests/fuzz/corpus build-fuzz/corpus
mkdir -p build-fuzz/crashes
./build-fuzz/tests/fuzz/quathinge_fuzz -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix=build-fuzz/crashes/ \
  build-fuzz/corpus 2>&1 | tee build-fuzz/fuzz.log | grep -E "^#[0-9]+ *(DONE|INITED)|stat::number_of_executed_units|stat::peak_rss|cov:" | tail -4

#!/usr/bin/env bash
# Installs the built QuatHinge into a scratch prefix, then configures, builds and runs tests/consumer against it.
#   consumer_test.sh <QuatHinge build dir> <scratch dir> <double precision ON/OFF>
set -euo pipefail
build=$1 scratch=$2 double=${3:-OFF}
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
cmake -S "$here" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" -j2 >/dev/null
"$scratch/build/consumer"
# The package must refuse a consumer asking for the other precision.
other=ON; [ "$double" = "ON" ] && other=OFF
if cmake -S "$here" -B "$scratch/build-mixed" -DCMAKE_PREFIX_PATH="$scratch/prefix" \
     -DQUATHINGE_DOUBLE_PRECISION=$other >"$scratch/mixed.log" 2>&1; then
  echo "consumer_test: a consumer asking for QUATHINGE_DOUBLE_PRECISION=$other was not refused" >&2
  exit 1
fi
grep -q "cannot be mixed" "$scratch/mixed.log"
echo "consumer_test: package found, consumer ran, mixed precision refused"

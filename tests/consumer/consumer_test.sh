#!/usr/bin/env bash
# Installs the built QuatHinge into a scratch prefix, then configures, builds and runs tests/consumer against it.
#   consumer_test.sh <QuatHinge build dir> <scratch dir> [double precision ON/OFF, default OFF]
# Checks: find_package(QuatHinge 0.1) works from the prefix, the consumer runs, it got the package's btScalar
# (BT_USE_DOUBLE_PRECISION arrives with the target, nothing set by the consumer), and a consumer asking for the
# other precision is refused.
set -euo pipefail
build=$1 scratch=$2 double=${3:-OFF}
here=$(cd "$(dirname "$0")" && pwd)
case "$double" in ON|on|1|TRUE|true) double=ON; want=8 other=OFF ;; *) double=OFF; want=4 other=ON ;; esac
rm -rf "${scratch:?}"
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
cmake -S "$here" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" -j2 >/dev/null
out=$("$scratch/build/consumer")
echo "$out"
grep -q "sizeof(btScalar)=$want " <<<"$out" || {
  echo "consumer_test: expected sizeof(btScalar)=$want for QUATHINGE_DOUBLE_PRECISION=$double" >&2; exit 1; }
# The package must refuse a consumer asking for the other precision.
if cmake -S "$here" -B "$scratch/build-mixed" -DCMAKE_PREFIX_PATH="$scratch/prefix" \
     -DQUATHINGE_DOUBLE_PRECISION=$other >"$scratch/mixed.log" 2>&1; then
  echo "consumer_test: a consumer asking for QUATHINGE_DOUBLE_PRECISION=$other was not refused" >&2
  exit 1
fi
grep -q "cannot be mixed" "$scratch/mixed.log"
echo "consumer_test: package found, consumer ran with sizeof(btScalar)=$want, mixed precision refused"

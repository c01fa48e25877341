#!/usr/bin/env bash
# Installs the built QuatHinge into a scratch prefix, then uses it as an outside project would.
#   consumer_test.sh <QuatHinge build dir> <scratch dir> [double precision ON/OFF, default OFF]
# Checks:
#  - CMake: find_package(QuatHinge 0.2) works from the prefix, tests/consumer builds and runs, and it got the package's
#    btScalar (BT_USE_DOUBLE_PRECISION arrives with the target, nothing set by the consumer); a consumer asking for
#    the other precision is refused.
#  - pkg-config: `g++ main.cpp $(pkg-config --cflags --libs quathinge)` (quathinge-float64 for double) builds the same
#    program, which runs with the same btScalar.
#  - shared build (BUILD_SHARED_LIBS=ON): the libraries carry SONAME libQuatHinge….so.<major.minor> and export the
#    public classes but none of the internal namespace quathinge.
#  - installed programs: bin/quathinge-compare runs a URDF scene with the models of <prefix>/share/quathinge/models
#    (and fails once the installed model is removed, so it was that copy it read).
set -euo pipefail
build=$1 scratch=$2 double=${3:-OFF}
here=$(cd "$(dirname "$0")" && pwd)
case "$double" in ON|on|1|TRUE|true) double=ON; want=8 other=OFF pc=quathinge-float64 ;;
                  *) double=OFF; want=4 other=ON pc=quathinge ;; esac
fail() { echo "consumer_test: $*" >&2; exit 1; }
rm -rf "${scratch:?}"
prefix=$scratch/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null

# ---- CMake package
cmake -S "$here" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$scratch/build" -j2 >/dev/null
out=$("$scratch/build/consumer")
echo "cmake:      $out"
grep -q "sizeof(btScalar)=$want " <<<"$out" || fail "expected sizeof(btScalar)=$want for QUATHINGE_DOUBLE_PRECISION=$double"
# The package must refuse a consumer asking for the other precision.
if cmake -S "$here" -B "$scratch/build-mixed" -DCMAKE_PREFIX_PATH="$prefix" \
     -DQUATHINGE_DOUBLE_PRECISION=$other >"$scratch/mixed.log" 2>&1; then
  fail "a consumer asking for QUATHINGE_DOUBLE_PRECISION=$other was not refused"
fi
grep -q "cannot be mixed" "$scratch/mixed.log" || fail "the refusal does not say why: $(cat "$scratch/mixed.log")"

# ---- pkg-config: a plain compiler line. The installed libdir is lib/ or lib/<multiarch>/ (GNUInstallDirs).
pcfile=$(find "$prefix" -name "$pc.pc" -path '*/pkgconfig/*' | head -n1)
[ -n "$pcfile" ] || fail "$pc.pc not installed under $prefix"
export PKG_CONFIG_PATH="$(dirname "$pcfile")${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
libdir=$(pkg-config --variable=libdir "$pc")
# Every -L directory in the run path (README's line): this prefix's, and a shared Bullet's outside the system
# directories (built from source into a prefix), whose SONAMEs are Debian's own (libBulletDynamics.so.3.24 …), so
# that without it the loader would take Debian's Bullet, of whatever precision, when both are installed.
rpath=$(pkg-config --libs-only-L "$pc" | sed 's/-L/-Wl,-rpath,/g')
# shellcheck disable=SC2046,SC2086  # the flags are meant to split
g++ -std=c++17 -O1 "$here/main.cpp" -o "$scratch/pc-app" $(pkg-config --cflags --libs "$pc") $rpath
out=$("$scratch/pc-app")
echo "pkg-config: $out"
grep -q "sizeof(btScalar)=$want " <<<"$out" || fail "pkg-config build: expected sizeof(btScalar)=$want"

# ---- shared libraries: SONAME and exported symbols
shopt -s nullglob
shared=("$libdir"/libQuatHinge*.so)
if [ ${#shared[@]} -gt 0 ]; then
  for lib in "${shared[@]}"; do
    soname=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
    base=$(basename "$lib" .so)
    [[ "$soname" =~ ^$base\.so\.[0-9]+\.[0-9]+$ ]] || fail "$lib: SONAME '$soname', expected $base.so.<major>.<minor>"
    [ -e "$libdir/$soname" ] || fail "$lib: $soname not installed"
    internal=$(nm -DC --defined-only "$lib" | grep -c ' quathinge::' || true)
    [ "$internal" -eq 0 ] || fail "$lib exports $internal symbols of the internal namespace quathinge::"
    echo "shared:     $(basename "$lib") SONAME $soname, $(nm -DC --defined-only "$lib" | grep -c btQuaternionHinge) btQuaternionHinge* symbols exported, none of quathinge::"
  done
  core=$libdir/libQuatHinge${pc#quathinge}.so
  nm -DC --defined-only "$core" | grep 'btQuaternionHingeConstraint::getHingeAngle() const' >/dev/null ||
    fail "$core does not export the public class"
  echo "shared:     RUNPATH of the installed $(basename "$core"): $(readelf -d "$core" | sed -n 's/.*(RUNPATH).*\[\(.*\)\]/\1/p')"
fi

# ---- installed programs and models (the URDF model check needs a build with the URDF scenes: urdfdom is optional)
if [ -x "$prefix/bin/quathinge-compare" ] && [ "${4:-ON}" != ON ]; then
  "$prefix/bin/quathinge-compare" --soak 60 -s chain10 -k quaternion -o "$scratch/compare-out" >"$scratch/compare.log" 2>&1 ||
    fail "installed quathinge-compare failed: $(tail -n5 "$scratch/compare.log")"
  grep -q "^chain10 *quaternion .*60" "$scratch/compare.log" || fail "no chain10 soak row: $(cat "$scratch/compare.log")"
  echo "programs:   bin/quathinge-compare ran chain10 (a build without the URDF scenes: no model file to look for)"
elif [ -x "$prefix/bin/quathinge-compare" ]; then
  models=$prefix/share/quathinge/models
  [ -f "$models/NOTICE.md" ] || fail "models installed without NOTICE.md"
  run() { env -u QUATHINGE_MODELS_DIR "$prefix/bin/quathinge-compare" --soak 60 -s pendulum5 -k quaternion \
            -o "$scratch/compare-out" >"$scratch/compare.log" 2>&1; }
  run || fail "installed quathinge-compare failed: $(tail -n5 "$scratch/compare.log")"
  ! grep -q "skipped" "$scratch/compare.log" || fail "installed quathinge-compare skipped: $(grep skipped "$scratch/compare.log")"
  grep -q "^pendulum5 *quaternion .*60" "$scratch/compare.log" || fail "no pendulum5 soak row: $(cat "$scratch/compare.log")"
  # The same run with the installed model removed must miss exactly that file.
  mv "$models/pendulum5.urdf" "$scratch/"
  run || true
  mv "$scratch/pendulum5.urdf" "$models/"
  grep -q "not found: $models/pendulum5.urdf" "$scratch/compare.log" ||
    fail "quathinge-compare did not look for its models in $models: $(grep pendulum5 "$scratch/compare.log")"
  echo "programs:   bin/quathinge-compare ran pendulum5 from $models (and missed it there once removed)"
fi
# ---- the installed manual, named by the installed programs' --help (share/doc/quathinge: QuatHingeInstall.cmake)
if [ -x "$prefix/bin/quathinge-compare" ]; then
  doc=$prefix/share/doc/quathinge
  for page in README.md docs/PEERS.md docs/ENERGY.md docs/images/error_vs_time.png hello/hello.cpp; do
    [ -f "$doc/$page" ] || fail "the install has no $doc/$page"
  done
  for program in quathinge-compare quathinge-bench quathinge-sweep; do
    [ -x "$prefix/bin/$program" ] || fail "$program not installed"
    help=$("$prefix/bin/$program" --help 2>&1) || fail "installed $program --help failed: $help"
    grep -q "is in $(cd "$doc/docs" && pwd -P)\$" <<<"$help" ||
      fail "installed $program --help does not name the installed manual $doc/docs"
  done
  echo "programs:   the manual installed in $doc, named by the installed programs' --help"
fi
echo "consumer_test: package found, consumer ran with sizeof(btScalar)=$want (CMake and pkg-config), mixed precision refused"

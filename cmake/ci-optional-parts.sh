#!/usr/bin/env bash
# CI: QuatHinge with its optional parts missing. Nothing is uninstalled: each part is hidden from CMake by an option
# (CMAKE_DISABLE_FIND_PACKAGE_<Package>=ON, QUATHINGE_WORLD_IMPORTER=OFF). Each configuration must say at configure
# time what it leaves out, build, and pass every test it registers; a missing required part must stop configure with
# the Debian package to install.
#   no-eigen     no Eigen: no stabilizer, no demos (they compare with it); the library and its tests
#   no-extras    no Bullet world importer, no urdfdom/tinyxml2, no GLFW: no .bullet scene and no import tests, no URDF
#                scenes and their tests, no viewer; the demos and every other test
#   required     GoogleTest, fmt, Bullet hidden in turn: configure fails naming libgtest-dev, libfmt-dev,
#                libbullet-dev (configure only)
#   bash cmake/ci-optional-parts.sh [WORKDIR [CONFIGURATION...]]   (default: a new temporary folder; all three)
# (Bullet without its extras, built from source with BUILD_EXTRAS=OFF, is cmake/ci-source-bullet.sh's.)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-$(mktemp -d /tmp/quathinge-optional.XXXXXX)}
mkdir -p "$work"
work=$(cd "$work" && pwd)
shift $(( $# > 0 ? 1 : 0 ))
configurations=("$@")
[ ${#configurations[@]} -gt 0 ] || configurations=(no-eigen no-extras required)
fail() { echo "ci-optional-parts: FAILED: $*" >&2; exit 1; }
# Left out of these builds' test runs (a ctest regular expression): the ragdoll worlds that step Bullet for a minute
# or more in all, whose code no optional part changes; README's builds, the portable build and the cross builds run
# them. Every other test runs: what a missing part changes is what they check.
leave_out='StabilizerRagdollDemo\.A|StabilizerMixed\.RagdollDemo|StabilizerEnergyScenes\.RestingBodies'

bash "$src/cmake/setup-debian.sh" --quick

# configure (its QuatHinge lines shown and kept in $dir.cfg), build, every registered test
build_and_test() {
  local name=$1; shift
  local dir=$work/$name start
  start=$(date +%s)
  echo; echo "=== ci-optional-parts: $name: $*"
  cmake -S "$src" -B "$dir" -DQUATHINGE_WERROR=ON "$@" >"$dir.cfg" 2>&1 || { cat "$dir.cfg"; fail "$name: configure"; }
  grep "QuatHinge" "$dir.cfg" || true
  cmake --build "$dir" -j2 >"$dir.log" 2>&1 || { grep -E -A8 "error" "$dir.log" | head -n 60; fail "$name: build"; }
  ctest --test-dir "$dir" --output-on-failure -j2 ${leave_out:+-E "$leave_out"} >"$dir-ctest.log" 2>&1 ||
    { cat "$dir-ctest.log"; fail "$name: tests"; }
  grep -E "tests passed|tests failed" "$dir-ctest.log"
  ctest --test-dir "$dir" -N >"$dir-tests.txt"
  echo "=== ci-optional-parts: $name passed in $(( $(date +%s) - start )) s"
}
expect_said() { grep -q -- "$2" "$work/$1.cfg" || fail "$1: configure did not say '$2'"; }
expect_no_test() { if grep -E -- "$2" "$work/$1-tests.txt"; then fail "$1: tests registered that need what is missing"; fi; }

for configuration in "${configurations[@]}"; do
  case "$configuration" in
    no-eigen)
      build_and_test no-eigen -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON
      expect_said no-eigen "the stabilizer (QuatHinge::Stabilizer) is not built"
      expect_said no-eigen "demos not built"
      if ls "$work"/no-eigen/plugin/stabilizer/libQuatHingeStabilizer* >/dev/null 2>&1; then fail "no-eigen: a stabilizer was built"; fi
      expect_no_test no-eigen "Stabilizer[A-Z][A-Za-z]*\."
      ;;
    no-extras)
      build_and_test no-extras -DQUATHINGE_WORLD_IMPORTER=OFF -DCMAKE_DISABLE_FIND_PACKAGE_urdfdom=ON \
        -DCMAKE_DISABLE_FIND_PACKAGE_tinyxml2=ON -DCMAKE_DISABLE_FIND_PACKAGE_glfw3=ON
      expect_said no-extras "the .bullet import tests are not registered"
      expect_said no-extras "no URDF scenes"
      expect_said no-extras "viewer skipped"
      [ ! -e "$work/no-extras/demos/viewer/quathinge-viewer" ] || fail "no-extras: a viewer was built"
      expect_no_test no-extras "Urdf\.|Spider|SerializeFile|Ownership|viewer_"
      # the demo runs its default scenes without the missing ones
      "$work/no-extras/demos/quathinge-compare" -d 0.5 --no-reference -o "$work/no-extras-demo" >"$work/no-extras-demo.log" 2>&1 ||
        { cat "$work/no-extras-demo.log"; fail "no-extras: quathinge-compare"; }
      if grep -i "spider" "$work/no-extras-demo.log"; then fail "no-extras: the demo ran the spider"; fi
      ;;
    required)
      echo; echo "=== ci-optional-parts: required parts"
      check_refused() {  # what, the package the message must name, environment and options...
        local what=$1 package=$2; shift 2
        if env "$@" -DQUATHINGE_WERROR=ON >"$work/required-$what.log" 2>&1; then fail "configure without $what passed"; fi
        grep -q -- "$package" "$work/required-$what.log" ||
          { cat "$work/required-$what.log"; fail "configure without $what does not name $package"; }
        echo "without $what: $(grep -m1 -A2 "CMake Error" "$work/required-$what.log" | tail -n +2 | tr -s ' \n' ' ')"
      }
      check_refused GTest libgtest-dev cmake -S "$src" -B "$work/required-gtest" -DCMAKE_DISABLE_FIND_PACKAGE_GTest=ON
      check_refused fmt libfmt-dev cmake -S "$src" -B "$work/required-fmt" -DCMAKE_DISABLE_FIND_PACKAGE_fmt=ON
      check_refused Bullet libbullet-dev PKG_CONFIG_LIBDIR="$work/no-pkgconfig" cmake -S "$src" -B "$work/required-bullet"
      ;;
    *) echo "usage: $0 [WORKDIR [no-eigen|no-extras|required]...]" >&2; exit 2 ;;
  esac
done
echo; echo "=== ci-optional-parts: all passed (${configurations[*]})"

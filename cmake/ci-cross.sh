#!/usr/bin/env bash
# CI: QuatHinge cross-built for another platform and tested there under an emulator, against a Bullet cross-built from
# Debian's source package (cmake/bullet-source.sh: Bullet 3.24, library only, float) and a GoogleTest cross-built from
# Debian's googletest source package (/usr/src/googletest). Library and stabilizer, no demos (they need urdfdom, GLFW
# ... of the target), -j2.
#   bash cmake/ci-cross.sh mingw   [WORKDIR]   Windows x86-64: MinGW-w64 (g++-mingw-w64-x86-64-posix), run by wine64
#   bash cmake/ci-cross.sh aarch64 [WORKDIR]   Linux ARM64: aarch64 GCC (g++-aarch64-linux-gnu), run by qemu-aarch64
# Each: every test of quathinge_tests (the library's and the stabilizer's; under qemu all but the 4 StabilizerMixed ones,
# for their time) in one run of the program under the emulator;
# then the package installed into a prefix and an outside program (tests/consumer: find_package(QuatHinge)) built
# against it with the same toolchain and run under the emulator.
# mingw also builds QuatHinge as DLLs over Bullet's DLLs (the supported shared combination, docs/PLATFORMS.md),
# linked with -Wl,--exclude-all-symbols so that only what QUATHINGE_API / QUATHINGE_STABILIZER_API mark is exported
# (MinGW would otherwise export everything and hide a missing mark): the export tables are checked, every test runs
# against the DLLs, and the consumer runs against the installed DLLs.
# WORKDIR (default: a new temporary folder) keeps Bullet's source, the Bullet and GoogleTest builds (reused within a
# run: a second call with the same WORKDIR rebuilds only QuatHinge) and the logs.
set -euo pipefail
target=${1:?usage: ci-cross.sh mingw|aarch64 [WORKDIR]}
src=$(cd "$(dirname "$0")/.." && pwd)
work=${2:-$(mktemp -d "/tmp/quathinge-cross-$target.XXXXXX")}
mkdir -p "$work"
work=$(cd "$work" && pwd)
fail() { echo "ci-cross $target: FAILED: $*" >&2; exit 1; }
t0=$(date +%s)
step_start=$t0
step() {  # prints the previous step's time and starts the next
  local now; now=$(date +%s)
  [ "$step_start" -eq "$t0" ] || echo "    ($(( now - step_start )) s)"
  step_start=$now
  echo; echo "=== ci-cross $target: $* ($(date -u +%T))"
}
case $target in
  mingw)
    packages=(g++-mingw-w64-x86-64-posix wine64)
    toolchain=$src/cmake/toolchains/x86_64-w64-mingw32.cmake
    exe=.exe ;;
  aarch64)
    packages=(g++-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user)
    toolchain=$src/cmake/toolchains/aarch64-linux-gnu.cmake
    exe= ;;
  *) fail "unknown target '$target' (mingw or aarch64)" ;;
esac
# Besides cmake/setup-debian.sh's packages (cmake, pkg-config, Eigen, googletest's source); ccache (below).
packages+=(googletest libeigen3-dev cmake pkg-config xz-utils ccache)
missing=()
for p in "${packages[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  step "apt-get install ${missing[*]}"
  as_root=()
  [ "$(id -u)" -eq 0 ] || as_root=(sudo)
  DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -qq -o DPkg::Lock::Timeout=600 --no-install-recommends "${missing[@]}" \
    >"$work/apt.log" 2>&1 || { tail -n 20 "$work/apt.log"; fail "apt-get install"; }
fi
# ccache, its cache in the work folder: within a run Bullet's DLL build for mingw compiles what its static build
# compiled (Bullet exports by the linker's default, no macros), about a minute and a half saved; a later run with the
# same work folder reuses it all. A cache of its own, so a run by hand times what CI's fresh machine does.
export CCACHE_DIR=$work/ccache
launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cross=(-DCMAKE_TOOLCHAIN_FILE="$toolchain" "${launcher[@]}")

# The emulator, as the toolchain file sets it for ctest: run <program> [args].
case $target in
  mingw)
    export WINEPREFIX=$work/wineprefix WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="
    unset DISPLAY
    mingw_dlls="$(dirname "$(x86_64-w64-mingw32-g++-posix -print-libgcc-file-name)");/usr/x86_64-w64-mingw32/lib"
    mingw_dlls=$(echo "$mingw_dlls" | sed 's|/|\\|g; s|\(^\|;\)\\|\1Z:\\|g')
    run() { WINEPATH="$mingw_dlls${run_path:+;$run_path}" /usr/lib/wine/wine64 "$@"; }
    winpath() { echo "Z:$1" | sed 's|/|\\|g'; } ;;
  aarch64)
    run() { qemu-aarch64 -L /usr/aarch64-linux-gnu "$@"; } ;;
esac
# Tests left out under the emulator (a gtest negative filter), each for its time: qemu translates every instruction.
# StabilizerMixed: its tests step Bullet's ragdoll demo with and without the stabilizer for seconds each (about 20 s
# natively, 12 times that under qemu-aarch64); StabilizerRagdollDemo's piles of 20 (5 and 3 min under qemu, one of them
# half of a shard's time) and crowds of 100 (half a minute each natively). Its one ragdoll on each ground runs. They
# run natively and under wine (in the static build; the DLL build's run leaves them out too: the same code, 2 min).
ragdoll_worlds='StabilizerMixed.*:StabilizerRagdollDemo.A*'
leave_out=
[ "$target" != aarch64 ] || leave_out=$ragdoll_worlds

run_path=

# ---- Bullet and GoogleTest for the target
step "Bullet source (apt-get source bullet)"
source "$src/cmake/bullet-source.sh"   # quathinge_bullet_source, build_bullet
if ls -d "$work"/bullet3-* >/dev/null 2>&1 && [ -f "$work/bullet-$target-static/lib/pkgconfig/bullet.pc" ]; then
  bullet_src=$(ls -d "$work"/bullet3-* | head -n1)
  echo "reusing $bullet_src"
else
  quathinge_bullet_source "$work"
fi
step "Bullet, static, for $target"
build_bullet "$target-static" "${cross[@]}"

step "GoogleTest from /usr/src/googletest, for $target"
gtest=$work/gtest-$target
if [ ! -d "$gtest/lib/cmake/GTest" ]; then
  cmake -S /usr/src/googletest -B "$work/gtest-build-$target" "${cross[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DBUILD_GMOCK=OFF -DINSTALL_GTEST=ON -DCMAKE_INSTALL_PREFIX="$gtest" -DCMAKE_INSTALL_LIBDIR=lib \
    >"$work/gtest-$target.log" 2>&1 || { cat "$work/gtest-$target.log"; fail "GoogleTest configure"; }
  cmake --build "$work/gtest-build-$target" -j2 >>"$work/gtest-$target.log" 2>&1 || { tail -n 30 "$work/gtest-$target.log"; fail "GoogleTest build"; }
  cmake --install "$work/gtest-build-$target" >>"$work/gtest-$target.log"
fi
ls "$gtest"/lib/*gtest*

# ---- QuatHinge
# configure_quathinge NAME BULLET-PREFIX [options]: the library, the stabilizer and the tests, no demos.
configure_quathinge() {
  local name=$1 bullet=$2; shift 2
  export PKG_CONFIG_LIBDIR=$bullet/lib/pkgconfig
  cmake -S "$src" -B "$work/qh-$name" "${cross[@]}" -DCMAKE_FIND_ROOT_PATH="$bullet;$gtest" \
    -DEigen3_DIR=/usr/share/eigen3/cmake -DQUATHINGE_WERROR=ON -DQUATHINGE_BUILD_DEMOS=OFF \
    -DCMAKE_INSTALL_PREFIX="$work/qh-$name-prefix" "$@" >"$work/qh-$name-configure.log" 2>&1 ||
    { cat "$work/qh-$name-configure.log"; fail "QuatHinge configure ($name)"; }
  grep "QuatHinge:" "$work/qh-$name-configure.log" || true
}
build_quathinge() {  # NAME targets...
  local name=$1; shift
  cmake --build "$work/qh-$name" -j2 --target "$@" >"$work/qh-$name-build.log" 2>&1 ||
    { grep -B5 -A20 -m3 -E "error|Error" "$work/qh-$name-build.log" | head -n 80; fail "QuatHinge build ($name)"; }
}
# run_tests NAME: every test of quathinge_tests (but $leave_out) in $shards processes at once (GoogleTest's sharding:
# qemu and the tests run one thread each, the machine has two cores); the summary lines, and the failures in full.
# Under wine the prefix is made first and one wineserver kept running for the run (start_wine): two wine processes
# starting at once on a new prefix race to create it (one exited, "chdir to …/server-…: No such file or directory").
shards=2
start_wine() {
  [ "$target" = mingw ] || return 0
  [ -f "$WINEPREFIX/system.reg" ] || { run wineboot --init >"$work/wineboot.log" 2>&1; /usr/lib/wine/wineserver64 -w; }
  /usr/lib/wine/wineserver64 -p
}
stop_wine() { [ "$target" != mingw ] || /usr/lib/wine/wineserver64 -k || true; }
run_tests() {
  local name=$1 log=$work/qh-$1-tests shard pids=() status=0 passed=0 skipped=0 n
  [ -z "$leave_out" ] || echo "left out: $leave_out"
  start_wine
  for ((shard = 0; shard < shards; ++shard)); do
    (cd "$work/qh-$name/tests" && GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$shard \
      run "./quathinge_tests$exe" --gtest_color=no ${leave_out:+--gtest_filter=-$leave_out}) >"$log-$shard.log" 2>&1 &
    pids+=($!)
  done
  for ((shard = 0; shard < shards; ++shard)); do
    wait "${pids[$shard]}" && continue
    status=1
    echo "shard $shard of $shards failed:"
    { grep -B2 -A25 -E "^\[  FAILED  \]|Failure" "$log-$shard.log" || true; } | head -n 150
    tail -n 30 "$log-$shard.log" || true
  done
  stop_wine
  [ "$status" -eq 0 ] || fail "tests ($name)"
  for ((shard = 0; shard < shards; ++shard)); do
    echo "shard $shard of $shards:"
    grep -E "^\[==========\]|^\[  PASSED  \]|^\[  SKIPPED \]|YOU HAVE" "$log-$shard.log" || true
    n=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) tests\?\..*/\1/p' "$log-$shard.log"); passed=$((passed + ${n:-0}))
    n=$(sed -n 's/^\[  SKIPPED \] \([0-9]*\) tests\?, listed.*/\1/p' "$log-$shard.log"); skipped=$((skipped + ${n:-0}))
  done
  [ "$passed" -gt 0 ] || fail "tests ($name): none passed"
  echo "ci-cross $target ($name): $passed passed, 0 failed$([ "$skipped" -eq 0 ] || echo ", $skipped skipped")"
}
# run_consumer NAME: tests/consumer against the installed package of qh-NAME, built with the same toolchain.
run_consumer() {
  local name=$1 bullet=$2 prefix=$work/qh-$1-prefix out
  cmake --install "$work/qh-$name" >"$work/qh-$name-install.log"
  rm -rf "$work/consumer-$name"
  cmake -S "$src/tests/consumer" -B "$work/consumer-$name" "${cross[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_FIND_ROOT_PATH="$prefix;$bullet" >"$work/consumer-$name.log" 2>&1 ||
    { cat "$work/consumer-$name.log"; fail "consumer configure ($name)"; }
  cmake --build "$work/consumer-$name" -j2 >>"$work/consumer-$name.log" 2>&1 ||
    { tail -n 40 "$work/consumer-$name.log"; fail "consumer build ($name)"; }
  out=$(cd "$work/consumer-$name" && run "./consumer$exe") || fail "consumer ($name) exited non-zero: $out"
  echo "consumer ($name, installed package in $prefix): $out"
  grep -q "sizeof(btScalar)=4 " <<<"$out" || fail "consumer ($name): expected sizeof(btScalar)=4"
}

step "QuatHinge, static, over the static Bullet: build"
configure_quathinge "$target-static" "$work/bullet-$target-static"
build_quathinge "$target-static" QuatHinge QuatHingeStabilizer quathinge_tests
step "QuatHinge, static: quathinge_tests under the emulator"
run_tests "$target-static"
step "QuatHinge, static: installed package + outside program (tests/consumer)"
run_consumer "$target-static" "$work/bullet-$target-static"

if [ "$target" = mingw ]; then
  step "Bullet, DLLs (BUILD_SHARED_LIBS=ON), for mingw"
  build_bullet mingw-shared "${cross[@]}" -DBUILD_SHARED_LIBS=ON
  step "QuatHinge DLLs over Bullet's DLLs (-Wl,--exclude-all-symbols): build"
  configure_quathinge mingw-shared "$work/bullet-mingw-shared" -DBUILD_SHARED_LIBS=ON \
    -DCMAKE_SHARED_LINKER_FLAGS=-Wl,--exclude-all-symbols
  build_quathinge mingw-shared QuatHinge QuatHingeStabilizer quathinge_tests
  # The export tables: the public classes, nothing of namespace quathinge (mangled _ZN9quathinge / _ZNK9quathinge).
  for dll in "$work/qh-mingw-shared/plugin/libQuatHinge.dll" "$work/qh-mingw-shared/plugin/stabilizer/libQuatHingeStabilizer.dll"; do
    [ -f "$dll" ] || fail "$dll not built"
    x86_64-w64-mingw32-objdump -p "$dll" | sed -n '/^\[Ordinal\/Name Pointer\] Table/,/^$/p' | sed 1d |
      awk '{print $NF}' | sed '/^$/d' >"$dll.exports"
    n=$(wc -l <"$dll.exports")
    internal=$(grep -c -E '^_ZN?K?9quathinge' "$dll.exports" || true)
    [ "$internal" -eq 0 ] || fail "$(basename "$dll") exports $internal symbols of namespace quathinge: $(grep -E '^_ZN?K?9quathinge' "$dll.exports" | head -n 5)"
    echo "$(basename "$dll"): $n exported symbols, none of namespace quathinge"
  done
  grep -q '^_ZNK27btQuaternionHingeConstraint13getHingeAngleEv$' "$work/qh-mingw-shared/plugin/libQuatHinge.dll.exports" ||
    fail "libQuatHinge.dll does not export btQuaternionHingeConstraint::getHingeAngle() const"
  grep -q 'btQuaternionHingeStabilizer' "$work/qh-mingw-shared/plugin/stabilizer/libQuatHingeStabilizer.dll.exports" ||
    fail "libQuatHingeStabilizer.dll does not export btQuaternionHingeStabilizer"
  # The DLLs a test program loads: QuatHinge's (beside their import libraries) and Bullet's (bin/).
  run_path="$(winpath "$work/qh-mingw-shared/plugin");$(winpath "$work/qh-mingw-shared/plugin/stabilizer");$(winpath "$work/bullet-mingw-shared/bin")"
  step "QuatHinge DLLs: quathinge_tests under wine"
  leave_out=$ragdoll_worlds
  run_tests mingw-shared
  step "QuatHinge DLLs: installed package + outside program"
  run_path="$(winpath "$work/qh-mingw-shared-prefix/bin");$(winpath "$work/bullet-mingw-shared/bin")"
  run_consumer mingw-shared "$work/bullet-mingw-shared"
  run_path=
fi
step "done"
echo "=== ci-cross $target: all passed in $(( ($(date +%s) - t0) / 60 )) min $(( ($(date +%s) - t0) % 60 )) s (work folder $work)"

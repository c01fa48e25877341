#!/usr/bin/env bash
# CI: QuatHinge against a Bullet built from source, with no system Bullet in sight. The source is Debian's source package
# of Bullet 3.24 (apt-get source; its upstream tarball, without Debian's patches, as a user building a Bullet release
# has it), built static, library only (no extras, demos, tests or Bullet 3), about a minute a build on 2 cores.
# Every pkg-config search is limited to that Bullet (PKG_CONFIG_LIBDIR), so Debian's bullet.pc cannot be picked up.
#  1. float, installed: QuatHinge finds it through its bullet.pc, says that it has no world importer (no .bullet
#     import tests registered), builds its libraries, and the installed package serves an outside CMake project and a
#     plain g++ + pkg-config build (tests/consumer); ldd shows no libBullet and the programs hold Bullet's code (nm).
#     The test suite itself runs against a static Bullet from this source in cmake/ci-cross.sh, under wine and qemu
#     (here it took 5 min of CPU a run for what those and README's builds already run; the demos run without the
#     importer in cmake/ci-optional-parts.sh).
#  2. super-project: add_subdirectory(<bullet source>) + add_subdirectory(<QuatHinge>) + a hinge app: builds and runs,
#     no compile line names /usr/include/bullet, no libBullet in ldd.
#  3. double (USE_DOUBLE_PRECISION=ON; its bullet.pc carries -DBT_USE_DOUBLE_PRECISION, no -float64 name): with the
#     default options QuatHinge follows it (through bullet.pc, and through -DBullet_DIR=<its BulletConfig.cmake> with
#     no pkg-config at all) and the consumer runs with sizeof(btScalar)=8; -DQUATHINGE_DOUBLE_PRECISION=OFF stops at
#     configure time naming both.
#   bash cmake/ci-source-bullet.sh [WORKDIR]   (default: a new temporary folder; adds a deb-src line if none, as root
#                                              or through sudo)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-$(mktemp -d /tmp/quathinge-source-bullet.XXXXXX)}
mkdir -p "$work"
work=$(cd "$work" && pwd)
fail() { echo "ci-source-bullet: FAILED: $*" >&2; exit 1; }
step() { echo; echo "=== ci-source-bullet: $* ($(date -u +%T))"; }
source "$src/cmake/bullet-source.sh"   # quathinge_bullet_source, build_bullet

# ---- Bullet's source
step "Bullet source (apt-get source bullet)"
quathinge_bullet_source "$work"

# No libBullet/libLinearMath from anywhere in ldd, and Bullet's own code inside the program.
check_links_no_shared_bullet() {
  local f
  for f in "$@"; do
    echo "ldd $(basename "$f"):"; ldd "$f" | sed 's/^/    /'
    if ldd "$f" | grep -E 'libBullet|libLinearMath'; then fail "$f links a shared Bullet"; fi
    nm -C "$f" | grep ' [TW] btDiscreteDynamicsWorld::stepSimulation' >/dev/null || fail "$f has no Bullet code of its own"
  done
}

# ---- 1. float Bullet, installed, found through its bullet.pc only
step "1. static float Bullet, installed"
build_bullet float
export PKG_CONFIG_LIBDIR=$work/bullet-float/lib/pkgconfig
echo "PKG_CONFIG_LIBDIR=$PKG_CONFIG_LIBDIR: $(pkg-config --list-all | tr '\n' ' ')"
cmake -S "$src" -B "$work/qh-float" -DQUATHINGE_WERROR=ON -DQUATHINGE_BUILD_DEMOS=OFF | grep "QuatHinge:" |
  tee "$work/qh-float.cfg"
grep -q "without a world importer" "$work/qh-float.cfg" || fail "configure does not say that this Bullet has no world importer"
if ctest --test-dir "$work/qh-float" -N | grep -E "Ownership|SerializeFile"; then fail "import tests registered without an importer"; fi
cmake --build "$work/qh-float" -j2 --target QuatHinge QuatHingeStabilizer >"$work/qh-float.log" 2>&1 ||
  { tail -n 40 "$work/qh-float.log"; exit 1; }
bash "$src/tests/consumer/consumer_test.sh" "$work/qh-float" "$work/consumer-float" OFF
check_links_no_shared_bullet "$work/consumer-float/pc-app" "$work/consumer-float/build/consumer"

# ---- 2. super-project: Bullet's source and QuatHinge's tree side by side, no pkg-config at all
step "2. super-project: add_subdirectory(bullet) + add_subdirectory(quathinge)"
export PKG_CONFIG_LIBDIR=$work/no-pkgconfig
mkdir -p "$work/super" "$PKG_CONFIG_LIBDIR"
cp "$src/tests/consumer/main.cpp" "$work/super/main.cpp"
cat >"$work/super/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.21)
project(SuperProject LANGUAGES C CXX)
set(CMAKE_CXX_STANDARD 17)
foreach(option BUILD_EXTRAS BUILD_UNIT_TESTS BUILD_CPU_DEMOS BUILD_BULLET2_DEMOS BUILD_OPENGL3_DEMOS BUILD_PYBULLET
               BUILD_BULLET3 INSTALL_LIBS)
  set(\${option} OFF CACHE BOOL "" FORCE)
endforeach()
add_subdirectory("$bullet_src" bullet)
add_subdirectory("$src" quathinge)
add_executable(app main.cpp)
target_link_libraries(app PRIVATE QuatHinge::QuatHinge)
EOF
cmake -S "$work/super" -B "$work/super-build" -DCMAKE_BUILD_TYPE=Release 2>"$work/super-configure.err" | grep "QuatHinge:"
cmake --build "$work/super-build" -j2 --target app >"$work/super.log" 2>&1 || { tail -n 40 "$work/super.log"; exit 1; }
"$work/super-build/app"
if grep -rl "/usr/include/bullet" "$work/super-build" --include=flags.make; then fail "a compile line names /usr/include/bullet"; fi
check_links_no_shared_bullet "$work/super-build/app"

# ---- 3. double Bullet: followed by default, refused when float is asked for
step "3. static double Bullet (USE_DOUBLE_PRECISION=ON)"
build_bullet double -DUSE_DOUBLE_PRECISION=ON
grep -q -- "-DBT_USE_DOUBLE_PRECISION" "$work/bullet-double/lib/pkgconfig/bullet.pc" || fail "double bullet.pc without the define"
export PKG_CONFIG_LIBDIR=$work/bullet-double/lib/pkgconfig
qh_lib_only=(-DQUATHINGE_WERROR=ON -DQUATHINGE_BUILD_DEMOS=OFF -DQUATHINGE_BUILD_TESTS=OFF)
cmake -S "$src" -B "$work/qh-double-pc" "${qh_lib_only[@]}" | grep "QuatHinge:" | tee "$work/qh-double-pc.cfg"
grep -q "BT_USE_DOUBLE_PRECISION=ON: pkg-config bullet" "$work/qh-double-pc.cfg" || fail "double bullet.pc not followed"
cmake --build "$work/qh-double-pc" -j2 >"$work/qh-double-pc.log" 2>&1 || { tail -n 40 "$work/qh-double-pc.log"; exit 1; }
bash "$src/tests/consumer/consumer_test.sh" "$work/qh-double-pc" "$work/consumer-double-pc" ON
if cmake -S "$src" -B "$work/qh-double-mismatch" "${qh_lib_only[@]}" -DQUATHINGE_DOUBLE_PRECISION=OFF \
     >"$work/mismatch.log" 2>&1; then
  fail "QUATHINGE_DOUBLE_PRECISION=OFF against a double Bullet configured"
fi
grep -A3 "CMake Error" "$work/mismatch.log" | head -n 6
grep -q "BT_USE_DOUBLE_PRECISION=ON" "$work/mismatch.log" || fail "the mismatch error does not name the Bullet's precision"

export PKG_CONFIG_LIBDIR=$work/no-pkgconfig
cmake -S "$src" -B "$work/qh-double-config" "${qh_lib_only[@]}" \
  -DBullet_DIR="$work/bullet-double/lib/cmake/bullet" | grep "QuatHinge:" | tee "$work/qh-double-config.cfg"
grep -q "BT_USE_DOUBLE_PRECISION=ON: BulletConfig.cmake" "$work/qh-double-config.cfg" || fail "Bullet_DIR not followed"
cmake --build "$work/qh-double-config" -j2 >"$work/qh-double-config.log" 2>&1 || { tail -n 40 "$work/qh-double-config.log"; exit 1; }
bash "$src/tests/consumer/consumer_test.sh" "$work/qh-double-config" "$work/consumer-double-config" ON
check_links_no_shared_bullet "$work/consumer-double-config/pc-app"

step "ci-source-bullet: all passed (work folder $work)"

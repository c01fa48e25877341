#!/usr/bin/env bash
# The docs' C++ snippets, built and run against the installed package as an outside app would (docs/CONTRIBUTING.md,
# "Snippets are tested").
#   snippets_test.sh <QuatHinge source dir> <QuatHinge build dir> <scratch dir> [double precision ON/OFF]
# 1. installs the build into <scratch>/prefix;
# 2. extract_snippets.py turns README.md's and docs/*.md's marked ```cpp blocks into apps, each with README's CMake
#    block (<!-- snippet: app-cmake -->) as its CMakeLists.txt;
# 3. builds each app with find_package (that CMakeLists.txt) and with pkg-config (README's compiler line), runs both;
#    the fragments app gets the .bullet files its fragment-loaded fragments also run on (spider.bullet, a file of
#    quaternion hinges written by this project), loaded by Bullet's btBulletWorldImporter;
# 4. builds the fragments app once more with AddressSanitizer and UBSan (the app only: the installed libraries are as
#    built) and runs it with leak detection on: a constraint deleted twice (snippet 3 on a loaded world) or never
#    fails the test.
set -euo pipefail
src=$1 build=$2 scratch=$3 double=${4:-OFF}
case "$double" in ON|on|1|TRUE|true) pc=quathinge-float64 suffix=-float64 ;; *) pc=quathinge suffix= ;; esac
fail() { echo "snippets_test: $*" >&2; exit 1; }
rm -rf "${scratch:?}"
prefix=$scratch/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
python3 "$src/tests/snippets/extract_snippets.py" "$src" "$scratch/apps" >"$scratch/apps.txt"
pcfile=$(find "$prefix" -name "$pc.pc" -path '*/pkgconfig/*' | head -n1)
[ -n "$pcfile" ] || fail "$pc.pc not installed under $prefix"
export PKG_CONFIG_PATH="$(dirname "$pcfile")${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
rpath=$(pkg-config --libs-only-L "$pc" | sed 's/-L/-Wl,-rpath,/g')
files=("$src/demos/models/spider.bullet" "$src/tests/data/quathinge_float.bullet")
args_of() { if [ "$1" = fragments ]; then echo "${files[@]}"; fi; }
apps=0
while read -r app; do
  dir=$scratch/apps/$app
  # CMake: the README's block as written
  cmake -S "$dir" -B "$dir/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >"$dir/cmake.log" 2>&1 ||
    fail "$app: configure failed: $(tail -n 20 "$dir/cmake.log")"
  cmake --build "$dir/build" -j2 >"$dir/build.log" 2>&1 || fail "$app: CMake build failed: $(tail -n 30 "$dir/build.log")"
  # shellcheck disable=SC2046  # the file names have no spaces
  "$dir/build/my_app" $(args_of "$app") >"$dir/run-cmake.log" 2>&1 || fail "$app (CMake) failed: $(tail -n 20 "$dir/run-cmake.log")"
  echo "cmake:      $app: $(tail -n1 "$dir/run-cmake.log")"
  # pkg-config: README's compiler line (the world importer's libraries as README names them)
  # shellcheck disable=SC2046,SC2086  # the flags are meant to split
  g++ -std=c++17 -O1 "$dir/main.cpp" -o "$dir/pc-app" $(pkg-config --cflags --libs "$pc") \
    -lBulletWorldImporter$suffix -lBulletFileLoader$suffix $rpath >"$dir/pc.log" 2>&1 ||
    fail "$app: pkg-config build failed: $(tail -n 30 "$dir/pc.log")"
  # shellcheck disable=SC2046
  "$dir/pc-app" $(args_of "$app") >"$dir/run-pc.log" 2>&1 || fail "$app (pkg-config) failed: $(tail -n 20 "$dir/run-pc.log")"
  echo "pkg-config: $app: $(tail -n1 "$dir/run-pc.log")"
  apps=$((apps + 1))
done <"$scratch/apps.txt"
[ "$apps" -gt 0 ] || fail "no snippet app was extracted"
# 4. the fragments under AddressSanitizer + UBSan, leak detection on
dir=$scratch/apps/fragments
# shellcheck disable=SC2046,SC2086
g++ -std=c++17 -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all "$dir/main.cpp" \
  -o "$dir/asan-app" $(pkg-config --cflags --libs "$pc") -lBulletWorldImporter$suffix -lBulletFileLoader$suffix \
  $rpath >"$dir/asan.log" 2>&1 || fail "fragments: sanitizer build failed: $(tail -n 30 "$dir/asan.log")"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 "$dir/asan-app" "${files[@]}" >"$dir/run-asan.log" 2>&1 ||
  fail "fragments under AddressSanitizer (detect_leaks=1) failed: $(tail -n 40 "$dir/run-asan.log")"
echo "asan+lsan:  fragments: $(tail -n1 "$dir/run-asan.log")"
echo "snippets_test: $apps apps built with find_package and with pkg-config, and ran"

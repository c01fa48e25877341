#!/usr/bin/env bash
# README's "Hello world": demos/hello built and run against the installed package as an outside app would.
#   hello_test.sh <QuatHinge source dir> <QuatHinge build dir> <scratch dir> <double precision ON/OFF> <compare ON/OFF>
# 1. installs the build into <scratch>/prefix;
# 2. builds demos/hello with its own CMakeLists.txt (find_package) and with pkg-config (README's compiler line, plus
#    -Wall -Wextra -Werror), runs both: each must return 0 (the stabilized run separated less than the stock one) and
#    print the two lines README shows;
# 3. compare ON: both outputs must equal README's expected output (the ```text block after <!-- hello-output -->)
#    character for character. The digits hold on the platform README names (x86-64, GCC, Bullet 3.24 float), so
#    tests/CMakeLists.txt turns the comparison on only in the native default build there; elsewhere steps 1–2 run.
set -euo pipefail
src=$1 build=$2 scratch=$3 double=${4:-OFF} compare=${5:-OFF}
case "$double" in ON|on|1|TRUE|true) pc=quathinge-float64 ;; *) pc=quathinge ;; esac
fail() { echo "hello_test: $*" >&2; exit 1; }
rm -rf "${scratch:?}"
mkdir -p "$scratch"
prefix=$scratch/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
cmake -S "$src/demos/hello" -B "$scratch/cmake" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  >"$scratch/cmake.log" 2>&1 || fail "configure failed: $(tail -n 20 "$scratch/cmake.log")"
cmake --build "$scratch/cmake" >"$scratch/build.log" 2>&1 || fail "CMake build failed: $(tail -n 30 "$scratch/build.log")"
"$scratch/cmake/hello" >"$scratch/out-cmake.txt" || fail "hello (CMake) returned $?: $(cat "$scratch/out-cmake.txt")"
pcfile=$(find "$prefix" -name "$pc.pc" -path '*/pkgconfig/*' | head -n1)
[ -n "$pcfile" ] || fail "$pc.pc not installed under $prefix"
export PKG_CONFIG_PATH="$(dirname "$pcfile")${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
rpath=$(pkg-config --libs-only-L "$pc" | sed 's/-L/-Wl,-rpath,/g')
# shellcheck disable=SC2046,SC2086  # the flags are meant to split
g++ -std=c++17 -O2 -Wall -Wextra -Werror "$src/demos/hello/hello.cpp" -o "$scratch/hello-pc" \
  $(pkg-config --cflags --libs "$pc") $rpath >"$scratch/pc.log" 2>&1 ||
  fail "pkg-config build failed: $(tail -n 30 "$scratch/pc.log")"
"$scratch/hello-pc" >"$scratch/out-pc.txt" || fail "hello (pkg-config) returned $?: $(cat "$scratch/out-pc.txt")"
cat "$scratch/out-cmake.txt"
form='^stock hinges(:                 | \+ the stabilizer:) largest joint separation [0-9.e+-]+ m$'
[ "$(grep -Ec "$form" "$scratch/out-cmake.txt")" = 2 ] && [ "$(wc -l <"$scratch/out-cmake.txt")" = 2 ] ||
  fail "hello printed something else than its two lines"
cmp -s "$scratch/out-cmake.txt" "$scratch/out-pc.txt" || fail "the CMake and pkg-config builds printed different output"
if [ "$compare" = ON ]; then
  awk '/<!-- hello-output -->/ {found = 1; next} found && /^```/ {if (inside) exit; inside = 1; next} inside {print}' \
    "$src/README.md" >"$scratch/readme.txt"
  [ -s "$scratch/readme.txt" ] || fail "README.md has no \`\`\`text block after <!-- hello-output -->"
  diff -u "$scratch/readme.txt" "$scratch/out-cmake.txt" ||
    fail "hello's output differs from README's expected output (README.md, \"Hello world\")"
  echo "hello_test: the output is README's"
else
  echo "hello_test: built with find_package and pkg-config, ran (README's digits are compared in the native float GCC build only)"
fi

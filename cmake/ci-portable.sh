#!/usr/bin/env bash
# CI: the portable build (-DQUATHINGE_PORTABLE=ON: standard C++17 alone, the path MSVC takes) under GCC and under
# Clang, each with -pedantic-errors -Werror on QuatHinge's own code (Bullet, Eigen and GoogleTest come in as system
# headers), and every test it registers.
#   bash cmake/ci-portable.sh [WORKDIR]          GCC: everything (library, stabilizer, demos, every test)
#                                               Clang: everything too (the default targets), built without
#                                               exceptions (-DQUATHINGE_EXCEPTIONS=OFF: the library, the stabilizer
#                                               and the tests with -fno-exceptions, refusals through the error
#                                               callback; the demos keep their own exceptions)
# (.ci/run runs the Clang build here and the GCC one as its shared-library build, with the same options.)
#   QUATHINGE_PORTABLE_COMPILERS="gcc clang"     which of them (default both)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-$(mktemp -d /tmp/quathinge-portable.XXXXXX)}
mkdir -p "$work"
work=$(cd "$work" && pwd)
bash "$src/cmake/setup-debian.sh" --quick
# The extensions themselves are off in this build by the macro; the source is also checked for any left outside it.
bash "$src/cmake/check-extensions.sh"
common=(-DQUATHINGE_PORTABLE=ON -DQUATHINGE_PEDANTIC=ON -DQUATHINGE_WERROR=ON)
for compiler in ${QUATHINGE_PORTABLE_COMPILERS:-gcc clang}; do
  start=$(date +%s)
  case "$compiler" in
    gcc) options=(-DCMAKE_CXX_COMPILER=g++) ;;
    clang) options=(-DCMAKE_CXX_COMPILER=clang++ -DQUATHINGE_EXCEPTIONS=OFF) ;;
    *) echo "ci-portable: unknown compiler $compiler (gcc, clang)" >&2; exit 2 ;;
  esac
  dir=$work/portable-$compiler
  echo "=== ci-portable: $compiler ${options[*]} ${common[*]}"
  cmake -S "$src" -B "$dir" "${common[@]}" "${options[@]}" | grep "QuatHinge"
  cmake --build "$dir" -j2 >"$dir.log" 2>&1 || { grep -E -B2 -A8 "error|warning" "$dir.log" | head -n 80; exit 1; }
  ctest --test-dir "$dir" --output-on-failure -j2 >"$dir-ctest.log" 2>&1 || { cat "$dir-ctest.log"; exit 1; }
  grep -E "tests passed|tests failed" "$dir-ctest.log"
  echo "=== ci-portable: $compiler passed in $(( $(date +%s) - start )) s"
done

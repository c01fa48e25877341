#!/usr/bin/env bash
# README's main job: set up, build (float, the default build/), run the comparison demo (stock hinge against the
# quaternion hinge). Arguments, if any, are passed to quathinge-compare (see --help); README runs it without.
set -euo pipefail
cd "$(dirname "$0")/.."
bash cmake/setup-debian.sh --quick
cmake -S . -B build -DQUATHINGE_WERROR=ON >/dev/null   # the same cache as run-tests.sh, so no rebuild in between
if ! cmake --build build -j2 --target quathinge-compare; then
  echo "run-demo: could not build quathinge-compare (is demos/CMakeLists.txt defining it?)" >&2
  exit 1
fi
demo=build/demos/quathinge-compare
[ -x "$demo" ] || { echo "run-demo: $demo was not built" >&2; exit 1; }
exec "./$demo" "$@"

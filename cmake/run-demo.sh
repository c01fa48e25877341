#!/usr/bin/env bash
# README's main job: set up, build, run the comparison demo (stock hinge against the quaternion hinge).
# Arguments are passed to quathinge-compare (see --help).
set -euo pipefail
cd "$(dirname "$0")/.."
bash cmake/setup-debian.sh
cmake -S . -B build -DQUATHINGE_WERROR=ON >/dev/null
cmake --build build -j2 --target quathinge-compare
exec ./build/demos/quathinge-compare "$@"

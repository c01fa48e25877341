#!/usr/bin/env bash
# The long soak (issue 6): a million steps of the 30-link chain and of the spider, with and without the stabilizer,
# each in its own process (so resident memory is per run). About five minutes on two cores. Writes the results into
# docs/TESTING.md between <!-- soak:begin --> and <!-- soak:end -->.
#   bash demos/make_soak.sh [steps]
set -euo pipefail
cd "$(dirname "$0")/.."
steps=${1:-1000000}
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j2 --target quathinge-compare
models=${QUATHINGE_MODELS_DIR:-demos/models}
out=demos/out/soak
mkdir -p "$out"
: >"$out/soak.txt"
# Every run goes into the table, a failed one too (its line says where it stopped); the script fails at the end.
failed=0
for run in "chain30 quaternion" "chain30 quaternion+stab" "spider quaternion" "spider quaternion+stab"; do
  set -- $run
  ./build/demos/quathinge-compare -s "$1" -k "$2" --soak "$steps" -j1 --models "$models" -o "$out/$1-$2" \
    >"$out/$1-$2.txt" || failed=1
  grep " steps " "$out/$1-$2.txt" >>"$out/soak.txt"
done
/usr/bin/python3 - "$out/soak.txt" <<'PY'
import sys
sys.path.insert(0, "demos")
from readme_section import replace
lines = open(sys.argv[1]).read().strip()
replace("soak", "```\n" + lines + "\n```", "docs/TESTING.md")
print(lines)
PY
[ "$failed" = 0 ] || { echo "make_soak: a run failed (its line above)" >&2; exit 1; }

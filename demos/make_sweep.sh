#!/usr/bin/env bash
# The row-basis sweep as published in docs/RESULTS.md: the bare quaternion hinge (its default rows) against stock
# btHingeConstraint on every scene of the library, the URDF robots and the inertia-ratio family, at 10, 20, 50, 100
# and 250 iterations, each scene at its own step:
#   bash demos/make_sweep.sh [--publish] [out-dir]   (default demos/out/sweep, git-ignored; under a minute on two cores)
# Writes sweep.csv (quathinge-sweep's runs), matched.csv (the same from matched states), sweep_report.md and sweep.png
# into out-dir; --publish also copies the plot
# to docs/images/row_basis_sweep.png and the report into docs/RESULTS.md between <!-- sweep:begin/end -->. The other bases
# and orders (docs/ROW_BASIS.md) are `quathinge-sweep -b ...`. QUATHINGE_SWEEP_BUILD picks the build (default build).
set -euo pipefail
cd "$(dirname "$0")/.."
publish=0
if [ "${1:-}" = --publish ]; then publish=1; shift; fi
out=${1:-demos/out/sweep}
build=${QUATHINGE_SWEEP_BUILD:-build}
bash cmake/setup-debian.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target quathinge-sweep
mkdir -p "$out"
# every scene of `quathinge-compare --list` but the two resting crowds (nothing moves: every figure is round-off),
# and the inertia-ratio family 1:10 to 1:1000
scenes=(pendulum chain10 chain30 chain100 heavy10 heavy100 heavy1000 heavy10000 double_pendulum rotor100 rotor1000
        flipped90 flipped179 flipped180 limit_hit limit_across_pi limit_wide motor_lift four_bar ragdoll spider
        kuka_iiwa pendulum5 humanoid base_2 quadruped two_joint_robot minitaur r2d2 panda
        inertia_ratio inertia_ratio_10 inertia_ratio_100 inertia_ratio_1000)
"$build/demos/quathinge-sweep" -s "${scenes[@]}" -b stock radial --orders point-first -i 10 20 50 100 250 -j 2 \
  -o "$out/sweep.csv" >"$out/sweep.txt"
# the same scenes and rows stepped from matched states: each kind's trajectory, both kinds' rows (docs/ROW_BASIS.md)
"$build/demos/quathinge-sweep" --matched -s "${scenes[@]}" -b radial --orders point-first -i 10 20 50 100 250 -j 2 \
  -o "$out/matched.csv" >"$out/matched.txt"
# the source the runs came from (what --publish writes, docs/RESULTS.md and the plot, is not a change to it), kept
# beside the output: the published section names no revision (the manual carries no commit hashes)
revision="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet HEAD -- . ':!docs/RESULTS.md' ':!docs/images' \
  2>/dev/null || echo ' + local changes')"
echo "$revision" >"$out/revision.txt"
note="Measured by \`bash demos/make_sweep.sh\` on $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(date -u +%Y-%m-%d); \
Bullet $(pkg-config --modversion bullet) float."
/usr/bin/python3 demos/sweep_report.py "$out/sweep.csv" --matched "$out/matched.csv" --out "$out" --note "$note"
if [ "$publish" = 1 ]; then
  cp "$out/sweep.png" docs/images/row_basis_sweep.png
  /usr/bin/python3 - "$out/sweep_report.md" <<'PY'
import sys
sys.path.insert(0, "demos")
from readme_section import replace
report = open(sys.argv[1]).read().strip()
replace("sweep", report + "\n\n![the sweep](images/row_basis_sweep.png)", "docs/RESULTS.md")
PY
  echo "make_sweep: docs/RESULTS.md and docs/images/row_basis_sweep.png updated" >&2
fi

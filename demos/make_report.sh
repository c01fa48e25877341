#!/usr/bin/env bash
# Regenerates every figure and the results table of docs/RESULTS.md from fresh runs:
#   bash demos/make_report.sh        (about a minute of runs on two cores, after the float and double builds)
# Uses Debian's own /usr/bin/python3 (python3-matplotlib). Writes the plots to docs/images/, the table to
# docs/images/results.md and into docs/RESULTS.md (between the results markers) and README.md's glance table (the
# glance markers), the energy table (make_energy.sh), the stabilized-joints and picture tables (make_joints.sh), the
# force scenes' table of docs/ENERGY.md (make_forces.sh), the raw CSV/JSON to demos/out/. demos/check_generated.sh
# regenerates the deterministic columns and compares.
# QUATHINGE_BUILD_DIR picks the build directory (default build/); QUATHINGE_MODELS_DIR the models (default demos/models).
set -euo pipefail
cd "$(dirname "$0")/.."
bash cmake/setup-debian.sh
build=${QUATHINGE_BUILD_DIR:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target quathinge-compare
compare=$build/demos/quathinge-compare
# the fine-step references run in double precision: Debian's double Bullet, in its own build (one program cannot
# link both precisions); QUATHINGE_REFERENCE_BUILD picks that directory (default build-double/)
reference_build=${QUATHINGE_REFERENCE_BUILD:-build-double}
cmake -S . -B "$reference_build" -DCMAKE_BUILD_TYPE=Release -DQUATHINGE_DOUBLE_PRECISION=ON >/dev/null
cmake --build "$reference_build" -j2 --target quathinge-compare
reference=(--reference-exe "$reference_build/demos/quathinge-compare")
out=demos/out/report
mkdir -p "$out"
models=${QUATHINGE_MODELS_DIR:-demos/models}
scenes_table=(pendulum chain10 chain30 heavy100 heavy1000 heavy10000 double_pendulum rotor100 flipped90 flipped179 flipped180
              limit_hit limit_across_pi limit_wide motor_lift four_bar ragdoll spider kuka_iiwa pendulum5 minitaur r2d2 panda
              inertia_ratio)
# 1. the table: every listed scene × kind at 60 Hz, 10 iterations, with references
$compare --models "$models" -s "${scenes_table[@]}" "${reference[@]}" -o "$out/table" >"$out/table.txt"
# 2. error against run time: step × iterations sweep (joint error needs no reference)
$compare --models "$models" -s pendulum chain10 heavy100 four_bar double_pendulum ragdoll --no-reference -d 3 \
  --sweep-dt 0.0333333 0.0166667 0.00833333 0.00416667 --sweep-iterations 2 5 10 20 50 -o "$out/sweep" >"$out/sweep.txt"
# 3. drift and energy over time
$compare --models "$models" -s pendulum chain10 heavy100 --no-reference --series -o "$out/series" >"$out/series.txt"
note="Measured by \`bash demos/make_report.sh\` on $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, \
$(date -u +%Y-%m-%d); 60 Hz, 10 iterations, Bullet $(pkg-config --modversion bullet) float; run time is each run's own \
thread CPU time; blow-up: the first step with a non-finite state, a body beyond 1e3 m or faster than 1e4 m/s, or energy \
above its start by more than 10× the energy scale (a runaway). Full data: \`$out/\`."
/usr/bin/python3 demos/plot_report.py --sweep "$out/sweep/results.json" --series "$out/series/results.json" \
  --table "$out/table/results.json" --images docs/images --markdown docs/images/results.md --readme docs/RESULTS.md --front README.md \
  --note "$note"
# 4. energy: stock, bare and stabilized at 60 and 240 Hz (docs/RESULTS.md, the energy markers; docs/images/energy_60s.png)
QUATHINGE_BUILD_DIR=$build bash demos/make_energy.sh
# 5. the stabilized joints (docs/STABILIZED_JOINTS.md) and the front page's picture (docs/RESULTS.md, the picture markers)
QUATHINGE_BUILD_DIR=$build bash demos/make_joints.sh
# 6. the force scenes of tests/test_stabilizer_forces.cpp, float and double (docs/ENERGY.md, the forces markers)
QUATHINGE_BUILD_DIR=$build QUATHINGE_REFERENCE_BUILD=$reference_build bash demos/make_forces.sh

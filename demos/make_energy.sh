#!/usr/bin/env bash
# The energy table and plot of docs/RESULTS.md (between the energy markers; docs/ENERGY.md explains them) and
# docs/ENERGY.md's table with the projection's own damping (the energy-damping markers):
#   bash demos/make_energy.sh        (about a minute on two cores, after the float build)
# Stock hinges, bare quaternion hinges and the stabilized ones (its defaults: keepEnergyAndMomentum) on the report's
# conservative and loaded scenes, 10 s at 60 and 240 Hz (10 iterations), plus the pendulum's energy over 60 s.
# Writes docs/images/energy_60s.png and the table; raw CSV/JSON to demos/out/energy/. QUATHINGE_BUILD_DIR picks the
# build directory (default build/). Also run as step 4 of demos/make_report.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${QUATHINGE_BUILD_DIR:-build}
compare=$build/demos/quathinge-compare
if [ ! -x "$compare" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build" -j2 --target quathinge-compare
fi
docs=${QUATHINGE_DOCS_DIR:-docs}   # the pages written (demos/check_generated.sh: a temporary copy)
out=${QUATHINGE_OUT_DIR:-demos/out}/energy
mkdir -p "$out"
models=${QUATHINGE_MODELS_DIR:-demos/models}
scenes=(pendulum double_pendulum four_bar pendulum5 chain10 chain30 rotor100 heavy100 heavy1000 heavy10000)
kinds=(stock quaternion quaternion+stab)
# the table runs add the projection's own damping (docs/ENERGY.md's energy-damping section)
$compare --models "$models" -s "${scenes[@]}" -k "${kinds[@]}" quaternion+stab-damped --no-reference -d 10 \
  -o "$out/60" >"$out/60.txt"
$compare --models "$models" -s "${scenes[@]}" -k "${kinds[@]}" quaternion+stab-damped --no-reference -d 10 \
  --dt 0.00416667 -o "$out/240" >"$out/240.txt"
$compare --models "$models" -s pendulum -k "${kinds[@]}" --no-reference -d 60 --series -o "$out/series60" >/dev/null
$compare --models "$models" -s pendulum -k "${kinds[@]}" --no-reference -d 60 --dt 0.00416667 --series \
  -o "$out/series240" >/dev/null
/usr/bin/python3 demos/energy_report.py --out "$out" --image "$docs/images/energy_60s.png" --readme "$docs/RESULTS.md" \
  --energy-page "$docs/ENERGY.md"

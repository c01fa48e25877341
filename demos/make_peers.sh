#!/usr/bin/env bash
# The peers report (docs/PEERS.md): every kind a Bullet user could pick instead of the quaternion hinge, each as its
# experts run it, against one common reference per scene, over step and iterations:
#   bash demos/make_peers.sh        (about 10 minutes on two shared cores, after the float and double builds)
# 1. the double build writes each scene's common reference over its first 3 s (demos/scenes/Reference.h): btMultiBody
#    for trees, the stock hinge at 100 iterations for the loop, Richardson-extrapolated from 1/15360 s and 1/30720 s,
#    with its halving change and the time a 1e-9 kick grows past 1e-6 m (the horizon ends before either exceeds its
#    bound);
# 2. the float build runs every scene x kind at 60, 120, 240, 480 Hz and 5, 10, 30 iterations over that horizon;
# 3. demos/plot_peers.py writes docs/images/peers_pareto.png, the choice table into docs/RESULTS.md (peers markers)
#    and the generated sections of docs/PEERS.md.
# Scenes: one of each class the choice table names (one joint, chains of 2, 10 and 30 links, a 1:100 mass ratio, the
# closed loop, a URDF robot); chain100 and the resting crowds are left out for time (and past the MLCP cap).
# QUATHINGE_BUILD_DIR / QUATHINGE_REFERENCE_BUILD pick the builds (default build/, build-double/).
set -euo pipefail
cd "$(dirname "$0")/.."
bash cmake/setup-debian.sh
build=${QUATHINGE_BUILD_DIR:-build}
reference_build=${QUATHINGE_REFERENCE_BUILD:-build-double}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target quathinge-compare
cmake -S . -B "$reference_build" -DCMAKE_BUILD_TYPE=Release -DQUATHINGE_DOUBLE_PRECISION=ON >/dev/null
cmake --build "$reference_build" -j2 --target quathinge-compare
out=demos/out/peers
rm -rf "$out"
mkdir -p "$out/grid"
models=${QUATHINGE_MODELS_DIR:-demos/models}
scenes=(pendulum double_pendulum chain10 chain30 heavy100 four_bar kuka_iiwa)
kinds=(stock stock+mlcp stock+nncg 6dof2 quaternion quaternion+mlcp quaternion+nncg quaternion+stab multibody
       multibody-damped)
start=$(date +%s)
# 1. references, two scenes at a time
printf '%s\n' "${scenes[@]}" | xargs -P 2 -I{} "$reference_build/demos/quathinge-compare" --models "$models" \
  --write-reference "$out/ref" -d 3 -s {} >"$out/references.txt"
{ grep -m1 '^scene,' "$out/references.txt"; grep -v '^scene,' "$out/references.txt"; } >"$out/references.csv"
# 2. the grid, each scene over its reference's horizon
grids=()
for scene in "${scenes[@]}"; do
  horizon=$(awk -F, -v s="$scene" '$1 == s { print $6 }' "$out/references.csv")
  "$build/demos/quathinge-compare" --models "$models" -s "$scene" -k "${kinds[@]}" --no-reference \
    --reference-dir "$out/ref" -d "$horizon" -j 2 \
    --sweep-dt 0.016666666666666666 0.008333333333333333 0.004166666666666667 0.0020833333333333333 \
    --sweep-iterations 5 10 30 -o "$out/grid/$scene" >"$out/grid/$scene.txt"
  grids+=("$out/grid/$scene/results.json")
done
# the Dantzig cap, said: a 100-link chain under the MLCP kinds is refused (500 rows > kMlcpMaxRows)
"$build/demos/quathinge-compare" --models "$models" -s chain100 -k stock+mlcp quaternion+mlcp --no-reference -d 0.1 \
  -o "$out/grid/cap" >"$out/grid/cap.txt"
grids+=("$out/grid/cap/results.json")
minutes=$(( ($(date +%s) - start + 59) / 60 ))
note="Measured by \`bash demos/make_peers.sh\` ($minutes min) on $(lscpu | sed -n 's/^Model name: *//p' | head -1), \
$(nproc) cores, $(date -u +%Y-%m-%d); Bullet $(pkg-config --modversion bullet) float; 60, 120, 240, 480 Hz x 5, 10, 30 \
iterations over each scene's reference horizon (docs/PEERS.md); run time: each run's own thread CPU time per simulated \
second; trajectory error: largest RMS over bodies of the distance to the common double-precision reference every 1/60 s."
/usr/bin/python3 demos/plot_peers.py --references "$out/references.csv" --grid "${grids[@]}" --images docs/images \
  --results docs/RESULTS.md --peers docs/PEERS.md --note "$note"

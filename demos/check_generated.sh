#!/usr/bin/env bash
# Regenerates the deterministic generated sections into a temporary copy of README.md and docs/ and fails on any
# difference from the committed ones (CI: cmake/ci-fresh-debian.sh runs it in the fresh root after README's commands):
#   bash demos/check_generated.sh        (30 s idle to 2.5 min busy on two cores, after the float and double builds)
# Sections: results (docs/RESULTS.md, every column but the run time, from the same runs as make_report.sh's table,
# references from the double build), glance (README.md), energy (docs/RESULTS.md), energy-damping and forces
# (docs/ENERGY.md; forces: the float and double test binaries, a few CPU seconds), stabilized-joints
# (docs/STABILIZED_JOINTS.md) and picture (docs/RESULTS.md). Not checked: the timed columns and tables (CPU ms /
# sim-s; bench, peers, sweep, soak: run time varies run to run) and the plots. The figures are bit-reproducible for a
# given platform and binary (the runs use no clock and no thread-count dependent order), not across compilers or
# CPUs: the committed sections come from the native float build of README's commands (GCC 12, x86-64, Bullet 3.24).
# QUATHINGE_BUILD_DIR / QUATHINGE_REFERENCE_BUILD pick the float and double builds (default build/, build-double/).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
build=${QUATHINGE_BUILD_DIR:-build}
reference_build=${QUATHINGE_REFERENCE_BUILD:-build-double}
for b in "$build" "$reference_build"; do
  [ -x "$b/demos/quathinge-compare" ] || cmake --build "$b" -j2 --target quathinge-compare
done
tmp=$(mktemp -d /tmp/quathinge-generated.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/docs/images" "$tmp/out"
cp README.md "$tmp/"
cp docs/*.md "$tmp/docs/"
compare=$build/demos/quathinge-compare
models=${QUATHINGE_MODELS_DIR:-demos/models}
# make_report.sh's step 1 (its scene list), the table alone
scenes_table=$(sed -n '/^scenes_table=(/,/)/p' demos/make_report.sh | tr -d '()\\\n' | sed 's/scenes_table=//')
# shellcheck disable=SC2086
$compare --models "$models" -s $scenes_table --reference-exe "$reference_build/demos/quathinge-compare" \
  -o "$tmp/out/table" >"$tmp/out/table.txt"
/usr/bin/python3 demos/plot_report.py --table "$tmp/out/table/results.json" --images "$tmp/docs/images" \
  --markdown "$tmp/out/results.md" --readme "$tmp/docs/RESULTS.md" --front "$tmp/README.md" --note "-" >/dev/null
QUATHINGE_BUILD_DIR=$build QUATHINGE_DOCS_DIR=$tmp/docs QUATHINGE_OUT_DIR=$tmp/out bash demos/make_energy.sh >/dev/null
QUATHINGE_BUILD_DIR=$build QUATHINGE_DOCS_DIR=$tmp/docs QUATHINGE_OUT_DIR=$tmp/out bash demos/make_joints.sh >/dev/null
QUATHINGE_BUILD_DIR=$build QUATHINGE_REFERENCE_BUILD=$reference_build QUATHINGE_DOCS_DIR=$tmp/docs \
  QUATHINGE_OUT_DIR=$tmp/out bash demos/make_forces.sh >/dev/null
/usr/bin/python3 demos/compare_sections.py . "$tmp" results glance energy energy-damping stabilized-joints picture forces
echo "check_generated: passed in $(( $(date +%s) - start )) s"

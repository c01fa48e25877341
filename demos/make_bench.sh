#!/usr/bin/env bash
# The benchmark against the stock hinge (issue 5): builds quathinge-bench (Release), runs every case with 5 repetitions
# (randomly interleaved, medians) and writes the ratio table and the scaling plot:
#   bash demos/make_bench.sh [--publish] [out-dir]   (default demos/out/bench, git-ignored; about three minutes on
#                                                     two cores)
# Writes bench.json (the raw run), machine.txt (lscpu), bench_report.md and scaling.png into out-dir; --publish also
# copies the plot to docs/images/bench_scaling.png and the report into docs/PERFORMANCE.md between <!-- bench:begin/end -->.
# Environment: QUATHINGE_BENCH_BUILD — build directory (default build); QUATHINGE_BENCH_FILTER — a benchmark regex
# (default: all); QUATHINGE_BENCH_REPETITIONS (default 5).
set -euo pipefail
cd "$(dirname "$0")/.."
publish=0
if [ "${1:-}" = --publish ]; then publish=1; shift; fi
out=${1:-demos/out/bench}
build=${QUATHINGE_BENCH_BUILD:-build}
bash cmake/setup-debian.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target quathinge-bench
mkdir -p "$out"
lscpu >"$out/machine.txt"
revision="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet HEAD 2>/dev/null || echo ' + local changes')"
cmd=("$build/demos/quathinge-bench" --benchmark_format=json
     "--benchmark_repetitions=${QUATHINGE_BENCH_REPETITIONS:-5}" --benchmark_report_aggregates_only=true
     --benchmark_enable_random_interleaving=true "--benchmark_filter=${QUATHINGE_BENCH_FILTER:-.}")
load=$(cut -d' ' -f1 /proc/loadavg)
if awk -v l="$load" -v n="$(nproc)" 'BEGIN { exit !(l > n / 2) }'; then
  echo "make_bench: load average $load on $(nproc) cores: other work will disturb the timings" >&2
fi
echo "running: ${cmd[*]}" >&2
"${cmd[@]}" >"$out/bench.json"
echo "$revision" >"$out/revision.txt"   # beside the output; the published section names no revision
/usr/bin/python3 demos/bench_report.py "$out/bench.json" --out "$out" --machine "$out/machine.txt" \
  --command "${cmd[*]} > $out/bench.json"
if [ "$publish" = 1 ]; then
  cp "$out/scaling.png" docs/images/bench_scaling.png
  /usr/bin/python3 - "$out/bench_report.md" <<'PY'
import re, sys
sys.path.insert(0, "demos")
from readme_section import replace
report = open(sys.argv[1]).read().strip()
report = report.replace("](scaling.png)", "](images/bench_scaling.png)")
# the report's own title becomes a sub-heading of the manual section
report = re.sub(r"^# .*\n", "", report, count=1).strip()
report = re.sub(r"^## ", "### ", report, flags=re.M)  # sub-sections of the performance page
replace("bench", report, "docs/PERFORMANCE.md")
PY
  echo "make_bench: docs/PERFORMANCE.md and docs/images/bench_scaling.png updated" >&2
fi

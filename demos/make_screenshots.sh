#!/usr/bin/env bash
# The manual's pictures from the viewer (docs/DEMOS.md, README), rendered headless under Xvfb:
#   bash demos/make_screenshots.sh        (a few seconds after the build)
# Writes docs/images/viewer_heavy1000.png (stock beside the stabilized quaternion hinge, panel and plots),
# docs/images/viewer_heavy1000_strip.png (the same at 0.25, 0.75, 1.25 and 1.75 s, stacked) and
# docs/images/viewer_spider.png (spider.bullet with stock, quaternion and quaternion+stab).
set -euo pipefail
cd "$(dirname "$0")/.."
bash cmake/setup-debian.sh
build=${QUATHINGE_VIEWER_BUILD:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target quathinge-viewer
viewer="$build/demos/viewer/quathinge-viewer"
models=${QUATHINGE_MODELS_DIR:-demos/models}
run() { xvfb-run -a -s "-screen 0 1280x720x24" "$viewer" --models "$models" "$@"; }
run --scenes heavy1000 --kinds stock,quaternion+stab --screenshot docs/images/viewer_heavy1000.png --frames 90
run --scenes heavy1000 --kinds stock,quaternion+stab --strip docs/images/viewer_heavy1000_strip.png \
    --strip-frames 15,45,75,105 --no-ui --size 960
run --scenes spider --kinds stock,quaternion,quaternion+stab --screenshot docs/images/viewer_spider.png --frames 120

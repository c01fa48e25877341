#!/usr/bin/env bash
# Installs the Debian 12 packages QuatHinge's build, tests, demos and reports need (as root, or through sudo).
# Idempotent. Every script of the project calls it before building, so by default it is cheap: when every package is
# already installed it does nothing at all (no apt-get update); otherwise it runs apt-get update and installs what is
# missing.
#   bash cmake/setup-debian.sh            as --quick (the default)
#   bash cmake/setup-debian.sh --quick    skip apt-get when every package is installed (checked with dpkg-query)
#   bash cmake/setup-debian.sh --update   always run apt-get update and install (refreshes the package lists)
set -euo pipefail

mode=quick
for arg in "$@"; do
  case "$arg" in
    --quick) mode=quick ;;
    --update) mode=update ;;
    *) echo "usage: $0 [--quick|--update]" >&2; exit 2 ;;
  esac
done

packages=(
  build-essential cmake pkg-config git
  libbullet-dev libbullet-extras-dev          # Bullet 3.24, float and double (-float64) builds; world importer
  libeigen3-dev                               # the stabilizer (private) and reference models
  libgtest-dev libgmock-dev libbenchmark-dev  # tests and the benchmark
  libcli11-dev nlohmann-json3-dev libfmt-dev  # the comparison demo
  liburdfdom-dev liburdfdom-headers-dev libtinyxml2-dev  # URDF scenes
  python3 python3-matplotlib                  # report plots
  clang libclang-rt-14-dev llvm valgrind     # fuzzing (libFuzzer + sanitizer runtimes, symbolizer); memory checks
  libglfw3-dev libimgui-dev libstb-dev xvfb   # the viewer (optional to the build) and its headless test;
  xauth                                       # xvfb-run needs it, and xvfb only recommends it (no recommends here)
  doxygen clang-format-14                     # the API reference (--target docs, 1.9.4) and the format check (14)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ "$mode" = quick ] && [ ${#missing[@]} -eq 0 ]; then
  echo "setup-debian: all ${#packages[@]} packages present"
  exit 0
fi

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup-debian: not root and no sudo; install: ${missing[*]:-nothing}" >&2; exit 1; }
  as_root=(sudo)
fi
# env, not a variable assignment before the command: sudo would drop it.
apt=("${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get)
"${apt[@]}" update -qq
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup-debian: installing ${missing[*]}"
  "${apt[@]}" install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
echo "setup-debian: done"

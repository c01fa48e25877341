#!/usr/bin/env bash
# Installs the Debian packages QuatHinge's build, tests, demos and reports need. Idempotent: when everything is
# already installed it does nothing (no apt-get update), so running it before every build is cheap.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libbullet-dev libbullet-extras-dev          # Bullet 3.24, float and double (-float64) builds; world importer
  libeigen3-dev                               # the stabilizer (private) and reference models
  libgtest-dev libgmock-dev libbenchmark-dev  # tests and the benchmark
  libcli11-dev nlohmann-json3-dev libfmt-dev  # the comparison demo
  liburdfdom-dev liburdfdom-headers-dev libtinyxml2-dev  # URDF scenes
  python3 python3-matplotlib                  # report plots
  clang valgrind                              # fuzzing (libFuzzer) and memory checks
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-debian: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "setup-debian: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup-debian: done"

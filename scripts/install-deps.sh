#!/usr/bin/env bash
# Installs the Debian 12 packages Sprig needs, only those missing.
# Checked with dpkg -s; installed with apt-get (after apt-get update) only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libglm-dev libembree-dev libtbb-dev libopenimageio-dev openimageio-tools
  libosd-dev libyaml-cpp-dev catch2 libcli11-dev libtinygltf-dev libopenvdb-dev libboost-iostreams-dev zlib1g-dev
  libbenchmark-dev parallel
  libmeshoptimizer-dev libcgal-demo
  clang-14 libclang-rt-14-dev ccache
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg -s "$p" >/dev/null 2>&1 || ! dpkg -s "$p" 2>/dev/null | grep -q '^Status: install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "sprig: installing missing packages: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"

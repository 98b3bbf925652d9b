#!/usr/bin/env bash
# Installs hairvox's dependencies from Debian 12 packages. Idempotent: apt-get
# runs (update once, then install) only when a package is missing.
# slurm-wlm and munge: the farm tests' one-node cluster (scripts/slurm-cluster.sh
# starts private daemons; the packages' own services are not used); ffmpeg:
# `hairvox sheet`'s movies and contact sheets.
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache
  libtbb-dev libglm-dev libcli11-dev nlohmann-json3-dev
  libopenvdb-dev libnanovdb-dev libopenvdb-tools python3-openvdb
  libboost-iostreams-dev libblosc-dev zlib1g-dev
  libopenexr-dev libimath-dev openexr libpng-dev
  libembree-dev libtinyobjloader-dev libhwy-dev libjemalloc-dev
  libgtest-dev libbenchmark-dev
  clang libclang-rt-14-dev
  python3-numpy python3-matplotlib
  python3-dev pybind11-dev libboost-python1.74-dev python3-pytest
  slurm-wlm munge ffmpeg
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

sudo=()
if [ "$(id -u)" -ne 0 ]; then sudo=(sudo); fi
echo "setup: installing ${missing[*]}"
"${sudo[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends \
  "${missing[@]}" >/dev/null
echo "setup: done"

#!/bin/sh
# Installs everything lensmith needs to build, test and fuzz on Debian 12 (run as root, or with sudo).
# Each package and what it is for is listed in README.md, section "Dependencies".
set -eu
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then exec sudo "$0" "$@"; fi
  echo "install-deps.sh: run as root (apt-get needs it)" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends \
  ca-certificates cmake ninja-build g++ pkg-config \
  libeigen3-dev libceres-dev libopenexr-dev libimath-dev libtiff-dev libpng-dev libjpeg62-turbo-dev libstb-dev libopencolorio-dev libdeflate-dev zlib1g-dev \
  nlohmann-json3-dev libcli11-dev catch2 libbenchmark-dev \
  clang libclang-rt-14-dev fonts-dejavu-core \
  python3 python3-dev pybind11-dev python3-numpy python3-matplotlib python3-pytest python3-pandas \
  slurm-wlm >/dev/null
echo "install-deps.sh: dependencies installed"

#!/usr/bin/env bash
# Installs the Debian packages lucent needs, and only those that are missing.
# Usage: scripts/install-deps.sh [--with-bench]   (--with-bench adds Embree for the benchmark)
set -euo pipefail

packages=(
  cmake g++ make pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-clhpp-headers
  libglm-dev libtinyobjloader-dev libstb-dev libgtest-dev
  nlohmann-json3-dev libcli11-dev libtinyexr-dev
  pybind11-dev python3-dev python3-numpy python3-pytest
)
if [[ "${1:-}" == "--with-bench" ]]; then packages+=(libembree-dev); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"

#!/usr/bin/env bash
# Installs the Debian packages lucent needs, and only those that are missing.
# Usage: scripts/install-deps.sh [--with-bench] [--with-format] [--with-fuzz] [--with-mpi]
#   --with-bench adds Embree for the benchmark; --with-format clang-format for the format check
#   (scripts/check-format.sh; CI's test run asks for it); --with-fuzz adds clang and its libFuzzer
#   and sanitizer runtimes for scripts/fuzz.sh (and the sanitizer build); --with-mpi adds OpenMPI
#   for lucent-mpi (optional: the project builds and tests without them).
set -euo pipefail

packages=(
  cmake g++ make ninja-build pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-clhpp-headers
  libglm-dev libtinyobjloader-dev libstb-dev libgtest-dev
  nlohmann-json3-dev libcli11-dev libtinyexr-dev
  pybind11-dev python3-dev python3-numpy python3-pytest
)
for arg in "$@"; do
  case "$arg" in
    --with-bench) packages+=(libembree-dev) ;;
    --with-format) packages+=(clang-format) ;;
    --with-fuzz) packages+=(clang libclang-rt-14-dev) ;;
    --with-mpi) packages+=(libopenmpi-dev openmpi-bin) ;;
    *) echo "install-deps: unknown option $arg (--with-bench, --with-format, --with-fuzz, --with-mpi)" >&2; exit 2 ;;
  esac
done

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

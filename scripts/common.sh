#!/usr/bin/env bash
# Shared by run.sh and test.sh: install what is missing, configure and build into build/.
set -euo pipefail
WB_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WB_BUILD="${WB_BUILD:-$WB_ROOT/build}"

# Debian packages the build and tests need (Qt and Xvfb only for the studio).
WB_PACKAGES=(cmake ninja-build g++ pkg-config libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev libpng-dev libzstd-dev libzip-dev zlib1g-dev
  qt6-base-dev xvfb xauth libgl1-mesa-dri)

wb_install_deps() {
  local missing=()
  for p in "${WB_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "wetbrush: installing ${missing[*]}"
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
}

wb_build() {
  local cuda_args=()
  if [ -z "${WB_CUDA:-}" ] && [ -x /usr/local/cuda/bin/nvcc ]; then
    cuda_args=(-DWB_CUDA=ON -DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc)
  elif [ -n "${WB_CUDA:-}" ]; then
    cuda_args=(-DWB_CUDA="$WB_CUDA")
  fi
  cmake -S "$WB_ROOT" -B "$WB_BUILD" -G Ninja -DCMAKE_BUILD_TYPE="${WB_BUILD_TYPE:-Release}" "${cuda_args[@]}"
  cmake --build "$WB_BUILD" --parallel "$(nproc)"
}

#!/usr/bin/env bash
# Shared by run.sh and test.sh: install what is missing, configure and build into build/.
set -euo pipefail
WB_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WB_BUILD="${WB_BUILD:-$WB_ROOT/build}"

# Debian packages the full build and its tests need: CLI, tests, benchmarks and the studio
# (Qt 6 Widgets and Test from qt6-base-dev, OpenGL and OpenGLWidgets from libqt6opengl6-dev; Xvfb
# and Mesa's software OpenGL for the studio's tests). scripts/check-packages.sh checks this list
# against the packages behind everything CMake finds.
WB_PACKAGES=(cmake ninja-build g++ pkg-config libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev libpng-dev libzstd-dev libzip-dev zlib1g-dev
  qt6-base-dev libqt6opengl6-dev xvfb xauth libgl1-mesa-dri
  # scripts/bundle-gpu.sh packs the studio for the GPU machine with the zstd program.
  zstd
  # What a painting becomes (docs/FORMATS.md): the float height map (OpenEXR), the glTF relief
  # (tinygltf) and the time-lapse video (FFmpeg's libraries; H.264 through Debian's libx264).
  libopenexr-dev libtinygltf-dev libavcodec-dev libavformat-dev libswscale-dev libavutil-dev
  # The Python module (python/, docs/PYTHON.md): Debian's Python headers, pybind11, and NumPy
  # and pytest for its tests.
  python3-dev pybind11-dev python3-numpy python3-pytest)

# The libFuzzer runs only (scripts/hardening.sh fuzz): clang with libFuzzer and its OpenMP.
WB_FUZZ_PACKAGES=(clang libclang-rt-dev libomp-dev)

# Installs the packages named, WB_PACKAGES when none are.
wb_install_deps() {
  local missing=() wanted=("$@")
  [ ${#wanted[@]} -eq 0 ] && wanted=("${WB_PACKAGES[@]}")
  for p in "${wanted[@]}"; do
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
  # Every product the README promises, whatever an earlier configure left in the cache.
  cmake -S "$WB_ROOT" -B "$WB_BUILD" -G Ninja -DCMAKE_BUILD_TYPE="${WB_BUILD_TYPE:-Release}" \
    -DWB_BUILD_STUDIO=ON -DWB_BUILD_TESTS=ON -DWB_BUILD_BENCH=ON "${cuda_args[@]}"
  cmake --build "$WB_BUILD" --parallel "$(nproc)"
}

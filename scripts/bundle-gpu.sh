#!/usr/bin/env bash
# Builds the CLI, tests and benchmarks with the CUDA backend for one GPU architecture and puts
# every shared library they need (except the C library and the driver) beside the binaries, so
# that build-gpu/bin runs on a machine that has a CUDA driver but none of our Debian packages.
#   scripts/bundle-gpu.sh [ARCH]      (ARCH defaults to 90, the H100/H200)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
source "$here/scripts/common.sh"
wb_install_deps
arch="${1:-90}"
build="$here/build-gpu"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DWB_CUDA=ON \
  -DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc -DCMAKE_CUDA_ARCHITECTURES="$arch" \
  -DWB_BUILD_STUDIO=OFF -DCMAKE_BUILD_RPATH='$ORIGIN' >/dev/null
cmake --build "$build" -j"$(nproc)" --target wetbrush wetbrush_tests wetbrush_bench
# Libraries from the toolchain and Debian packages; glibc's own and the driver's stay behind.
for exe in "$build"/bin/wetbrush "$build"/bin/wetbrush_tests "$build"/bin/wetbrush_bench; do
  ldd "$exe" | awk '/=> \// {print $3}' | while read -r lib; do
    case "$(basename "$lib")" in
      libc.so*|libm.so*|libdl.so*|libpthread.so*|librt.so*|ld-linux*|libcuda.so*) ;;
      *) [ "$(dirname "$lib")" = "$build/bin" ] || cp -uL "$lib" "$build/bin/" ;;
    esac
  done
done
echo "bundled: $(ls "$build/bin" | tr '\n' ' ')"

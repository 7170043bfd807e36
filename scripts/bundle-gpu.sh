#!/usr/bin/env bash
# Builds the CLI, tests, benchmarks and the studio with the CUDA backend for one GPU architecture.
# The first three go into build-gpu/bin with every shared library they need (except the C library
# and the driver) beside them, so that build-gpu/bin runs on a machine that has a CUDA driver but
# none of our Debian packages. The studio goes with its Qt libraries, the Qt plugins it loads on
# the offscreen platform and a font into one archive, build-gpu/studio.tar.zst (kept under 40 MiB:
# the GPU machine takes 64 MiB of files a run), with a zstd to unpack it in build-gpu/zstd;
# `scripts/gpu-run.sh OUT studio` unpacks and runs it.
#   scripts/bundle-gpu.sh [ARCH]               (ARCH defaults to 90, the H100/H200)
#   scripts/bundle-gpu.sh --pack-studio BUILD  (packs BUILD/bin/wetbrush-studio, built already, into
#                                               BUILD/studio.tar.zst: the archive's check on a
#                                               machine without a GPU, with a CPU build)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
source "$here/scripts/common.sh"

# Copies the shared libraries that the executables or plugins $2... need into $1, except the C
# library's own and the driver's (the machine's), and those already there.
copy_libs() {
  local dest="$1"; shift
  for f in "$@"; do
    ldd "$f" | awk '/=> \// {print $3}' | while read -r lib; do
      case "$(basename "$lib")" in
        libc.so*|libm.so*|libdl.so*|libpthread.so*|librt.so*|ld-linux*|libcuda.so*) ;;
        *) [ "$(dirname "$lib")" = "$dest" ] || cp -uL "$lib" "$dest/" ;;
      esac
    done
  done
}

# BUILD/bin/wetbrush-studio with what it loads on the offscreen platform -> BUILD/studio.tar.zst:
# studio/wetbrush-studio, studio/lib (libraries), studio/plugins (Qt plugins: the offscreen
# platform, and the image formats Qt loads to save the screenshot), studio/fonts and
# studio/fonts.conf (fontconfig finds no fonts on a machine without them: no text is drawn).
pack_studio() {
  local build="$1"
  local stage="$build/studio" archive="$build/studio.tar.zst"
  local plugins
  plugins="$(qtpaths6 --query QT_INSTALL_PLUGINS 2>/dev/null || echo /usr/lib/x86_64-linux-gnu/qt6/plugins)"
  rm -rf "$stage" "$archive"
  mkdir -p "$stage/lib" "$stage/plugins/platforms" "$stage/plugins/imageformats" "$stage/fonts"
  cp "$build/bin/wetbrush-studio" "$stage/"
  cp "$plugins"/platforms/libqoffscreen.so* "$stage/plugins/platforms/"
  cp "$plugins"/imageformats/*.so* "$stage/plugins/imageformats/"
  copy_libs "$stage/lib" "$stage/wetbrush-studio" "$stage"/plugins/*/*.so
  local font
  for font in /usr/share/fonts/truetype/dejavu/DejaVuSans{,-Bold}.ttf; do  # fontconfig's own (fonts-dejavu-core)
    if [ -f "$font" ]; then cp "$font" "$stage/fonts/"; else echo "warning: no $font: the studio draws no text there" >&2; fi
  done
  cat > "$stage/fonts.conf" <<'EOF'
<?xml version="1.0"?>
<!DOCTYPE fontconfig SYSTEM "urn:fontconfig:fonts.dtd">
<fontconfig>
  <dir prefix="relative">fonts</dir>
  <cachedir>/tmp/wetbrush-studio-fontconfig</cachedir>
</fontconfig>
EOF
  tar -C "$build" -cf - studio | zstd -19 -T0 -q -o "$archive"
  # A zstd to unpack it with, for a machine that has none.
  rm -rf "$build/zstd" && mkdir -p "$build/zstd"
  cp "$(command -v zstd)" "$build/zstd/"
  copy_libs "$build/zstd" "$build/zstd/zstd"
  local size unpacked
  size="$(stat -c %s "$archive")"
  unpacked="$(du -sm "$stage" | cut -f1)"
  echo "studio archive: $archive, $(awk -v b="$size" 'BEGIN {printf "%.1f", b / 1048576}') MiB" \
    "($unpacked MiB unpacked, $(find "$stage" -type f | wc -l) files)"
  if [ "$size" -gt $((40 * 1048576)) ]; then
    echo "the studio archive is over 40 MiB: the GPU machine takes 64 MiB of files a run" >&2
    exit 1
  fi
}

# The archive's compressor (Debian's zstd; the build needs only libzstd).
if ! command -v zstd >/dev/null; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends zstd
fi

if [ "${1:-}" = "--pack-studio" ]; then
  pack_studio "$(cd "${2:?build directory}" && pwd)"
  exit 0
fi

wb_install_deps
arch="${1:-90}"
build="$here/build-gpu"
# Without the relief and video exports (WB_MEDIA): FFmpeg's libraries and theirs (150 MiB) would
# not fit the 64 MiB the GPU machine takes; nothing measured there uses them.
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DWB_CUDA=ON \
  -DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc -DCMAKE_CUDA_ARCHITECTURES="$arch" \
  -DWB_BUILD_STUDIO=ON -DWB_MEDIA=OFF -DWB_PYTHON=OFF -DCMAKE_BUILD_RPATH='$ORIGIN' >/dev/null
cmake --build "$build" -j"$(nproc)" --target wetbrush wetbrush_tests wetbrush_bench wetbrush-studio
# Libraries from the toolchain and Debian packages; glibc's own and the driver's stay behind.
copy_libs "$build/bin" "$build"/bin/wetbrush "$build"/bin/wetbrush_tests "$build"/bin/wetbrush_bench
pack_studio "$build"
rm "$build/bin/wetbrush-studio"  # it is in the archive: build-gpu/bin stays what the other runs carry
echo "bundled: $(ls "$build/bin" | tr '\n' ' ')"

#!/usr/bin/env bash
# Checks the install list (WB_PACKAGES in scripts/common.sh) against what the build really uses:
# configures the project in a fresh build directory with CMake's package registries off, takes
# every package directory, library and program that CMake found (CMakeCache.txt), names the
# Debian package that ships it (dpkg -S), and fails when that package is neither in the list nor
# installed by it (its Depends, recursively). A new machine is verified by this check plus a
# fresh clone's scripts/test.sh (README, "A new machine").
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cuda_args=()
[ -x /usr/local/cuda/bin/nvcc ] && cuda_args=(-DWB_CUDA=ON -DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc)
if ! cmake -S "$WB_ROOT" -B "$tmp/build" -G Ninja -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON \
    -DCMAKE_FIND_PACKAGE_NO_SYSTEM_PACKAGE_REGISTRY=ON -DWB_BUILD_STUDIO=ON -DWB_BUILD_TESTS=ON \
    -DWB_BUILD_BENCH=ON "${cuda_args[@]}" > "$tmp/configure.log" 2>&1; then
  cat "$tmp/configure.log"
  echo "check-packages: configuring a fresh build failed (above)" >&2
  exit 1
fi

# Everything WB_PACKAGES installs: the packages and their Depends/Pre-Depends, recursively.
apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
  --no-replaces --no-enhances "${WB_PACKAGES[@]}" 2>/dev/null |
  sed -n 's/^\([a-z0-9][a-z0-9.+-]*\)\(:[a-z0-9]*\)\{0,1\}$/\1/p' | sort -u > "$tmp/closure"
printf '%s\n' "${WB_PACKAGES[@]}" | sort -u > "$tmp/listed"

# What CMake found: package directories (their config file), libraries and programs.
owner() {  # the Debian package that ships $1, or nothing
  dpkg -S "$1" 2>/dev/null | head -n1 | sed 's/:[^ ]*: .*//; s/: .*//' ||
    true
}
missing=0
printf '%-44s %-28s %s\n' "found by CMake" "Debian package" "in the install list"
while IFS='=' read -r key value; do
  name=${key%%:*}
  case "$name" in
    # Not packages: the install prefix and include directories (their libraries name the package).
    CMAKE_INSTALL_PREFIX | WB_CCCL_INCLUDE | *_INCLUDE_DIR* | *INCLUDEDIR*) continue ;;
    # Optional libraries FindOpenGL (through Qt) records when a machine has them; nothing links them.
    OPENGL_egl_LIBRARY | OPENGL_glu_LIBRARY | OPENGL_gles*_LIBRARY) continue ;;
  esac
  [ -e "$value" ] || continue
  case "$value" in "$WB_ROOT"/* | "$tmp"/*) continue ;; esac
  path=$value
  if [ -d "$path" ]; then
    # A config-mode package: the file CMake read.
    path=$(ls "$path"/*[Cc]onfig.cmake "$path"/*-config.cmake 2>/dev/null | head -n1 || true)
    [ -n "$path" ] || continue
  fi
  pkg=$(owner "$path")
  [ -n "$pkg" ] || pkg=$(owner "$(realpath "$path")")
  if [ -z "$pkg" ]; then
    status="outside Debian's packages ($path)"
  elif grep -qx "$pkg" "$tmp/listed"; then
    status="listed"
  elif grep -qx "$pkg" "$tmp/closure"; then
    status="installed by the list"
  else
    status="MISSING from WB_PACKAGES ($path)"
    missing=1
  fi
  printf '%-44s %-28s %s\n' "$name" "${pkg:--}" "$status"
done < <(grep -E '^[A-Za-z0-9_]+:(FILEPATH|PATH)=/' "$tmp/build/CMakeCache.txt" | sort -u)

if [ "$missing" -ne 0 ]; then
  echo "check-packages: add the packages marked MISSING to WB_PACKAGES in scripts/common.sh" >&2
  exit 1
fi
echo "check-packages: every package the build finds is installed by scripts/common.sh"

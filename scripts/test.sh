#!/usr/bin/env bash
# Installs what is missing, builds (CPU and, when nvcc exists, CUDA backends) and runs every test.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
wb_install_deps
wb_build
cd "$WB_BUILD"
ctest --output-on-failure --parallel "$(nproc)" --timeout 900

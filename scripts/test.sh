#!/usr/bin/env bash
# Installs what is missing, builds (CPU and, when nvcc exists, CUDA backends) and runs every test.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
wb_install_deps
wb_build
cd "$WB_BUILD"
# Two test processes share the two cores: OpenMP threads must sleep, not spin, while they wait.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"
ctest --output-on-failure --parallel "$(nproc)" --timeout 900

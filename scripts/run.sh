#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job: the painting studio when there is a
# display; when there is none (DISPLAY and WAYLAND_DISPLAY unset), a headless replay of an example
# stroke into out/replay.png (with its stats in out/replay-stats.json).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
wb_install_deps
wb_build
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  studio="$WB_BUILD/bin/wetbrush-studio"
  if [ ! -x "$studio" ]; then
    reason="the build did not produce it"
    grep -q '^WB_BUILD_STUDIO:BOOL=OFF' "$WB_BUILD/CMakeCache.txt" 2>/dev/null &&
      reason="$WB_BUILD was configured with -DWB_BUILD_STUDIO=OFF"
    echo "wetbrush: ERROR: studio not built ($reason): $studio is missing" >&2
    exit 1
  fi
  # The main job: the painting studio (quality preset chosen from the device).
  exec "$studio" "$@"
fi
echo "wetbrush: no display (DISPLAY and WAYLAND_DISPLAY are unset): running the headless demo replay instead of the studio"
mkdir -p "$WB_ROOT/out"
"$WB_BUILD/bin/wetbrush" devices
"$WB_BUILD/bin/wetbrush" replay "$WB_ROOT/examples/press-and-drag.json" \
  -o "$WB_ROOT/out/replay.png" --stats "$WB_ROOT/out/replay-stats.json" "$@"
echo "wetbrush: wrote $WB_ROOT/out/replay.png and $WB_ROOT/out/replay-stats.json"

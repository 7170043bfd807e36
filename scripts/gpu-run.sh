#!/usr/bin/env bash
# Runs what scripts/bundle-gpu.sh built on a machine with a CUDA GPU: the test suite on the
# CUDA backend, the benchmarks, the step bench of the examples and their replays, writing logs,
# stats and pictures to DIR; on request compute-sanitizer over the kernels' own tests, a soak, and
# the studio's scripted demo (from build-gpu/studio.tar.zst alone: build-gpu/bin is not needed).
#   scripts/gpu-run.sh DIR [tests|bench|steps|replay|sanitize|soak|studio]...   (the first four when
#   none is named; WB_SOAK_MINUTES sets the soak's length, default 4; WB_STUDIO_DEVICE and
#   WB_STUDIO_PRESET the studio's device and preset, default cuda and gpu, WB_STUDIO_ARGS more of
#   its options; WB_GPU_BUILD the build folder, default build-gpu)
set -uo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?output directory}"; shift
what="${*:-tests bench steps replay}"
build="$(realpath -m "${WB_GPU_BUILD:-$here/build-gpu}")"
bin="$build/bin"
export LD_LIBRARY_PATH="$bin${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"
[ -x "$bin/wetbrush" ] && "$bin/wetbrush" devices | tee -a "$out/gpu.txt"
for w in $what; do
  case "$w" in
    tests)
      WB_DEVICE=cuda timeout 400 "$bin/wetbrush_tests" --gtest_brief=1 > "$out/tests-cuda.log" 2>&1
      echo "tests (cuda): exit $?"; grep -E "^\[  (PASSED|FAILED)|FAILED  \]|tests ran" "$out/tests-cuda.log" | head -40 ;;
    bench)
      WB_DEVICE=cuda timeout 300 "$bin/wetbrush_bench" --benchmark_min_time=0.2 \
        --benchmark_out="$out/bench-cuda.json" --benchmark_out_format=json > "$out/bench-cuda.txt" 2>&1
      echo "bench (cuda): exit $?"; grep -E "^BM_" "$out/bench-cuda.txt" ;;
    steps)
      # `wetbrush bench` per example: the median step and its stages, host reads and launches.
      for ex in stab-and-roll tablet-scribble press-and-drag; do
        f="$(ls "$here"/examples/$ex.* | head -1)"
        timeout 120 "$bin/wetbrush" bench "$f" --device cuda --json "$out/steps-$ex.json" > "$out/steps-$ex.txt" 2>&1
        echo "steps $ex (cuda): exit $?"; grep -E "sim.step|host" "$out/steps-$ex.txt" | head -4
      done ;;
    replay)
      "$here/scripts/gallery.sh" "$out" cuda "$bin" ;;
    sanitize)
      # Out-of-bounds and uninitialised accesses, and shared-memory races, in the kernels whose
      # tests build them whole: the scans, the block sums, the recorded graphs, the CG.
      cs="$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)"
      filter='AlgorithmsTest.*:WickTest.*:BrushSamplesTest.*:GridStepTest.ViscousSolve*'
      for tool in memcheck racecheck; do
        WB_DEVICE=cuda timeout 120 "$cs" --tool "$tool" --error-exitcode 3 "$bin/wetbrush_tests" --gtest_brief=1 \
          --gtest_filter="$filter" > "$out/sanitize-$tool.log" 2>&1
        echo "compute-sanitizer $tool: exit $?"; grep -E "ERROR SUMMARY|RACECHECK SUMMARY|PASSED|FAILED" "$out/sanitize-$tool.log" | head -5
      done ;;
    soak)
      # Device and host memory over many runs back to back (docs/PERFORMANCE.md "Soak").
      m="${WB_SOAK_MINUTES:-4}"
      timeout $(( m * 60 + 120 )) "$bin/wetbrush" soak "$here"/examples/press-and-drag.json \
        "$here"/tests/data/strokes/good/minimal.json "$here"/tests/data/strokes/good/tablet.txt --minutes "$m" \
        --device cuda --json "$out/soak.json" > "$out/soak.txt" 2>&1
      echo "soak (cuda, $m min): exit $?"; tail -4 "$out/soak.txt" ;;
    studio)
      # The studio's scripted demo on the offscreen platform (no display, no OpenGL: the raster
      # view), from its archive: simulation rate, view frame rate, pen-to-paint latency
      # (studio-stats.json) and the window's picture (studio.png); docs/STUDIO.md "On a GPU".
      run="$build/studio-run"
      rm -rf "$run" && mkdir -p "$run"
      zstd_bin="$(command -v zstd || echo "$build/zstd/zstd")"  # bundle-gpu.sh's, where none is installed
      LD_LIBRARY_PATH="$build/zstd" "$zstd_bin" -dcq "$build/studio.tar.zst" | tar -C "$run" -xf -
      s="$run/studio"
      dev="${WB_STUDIO_DEVICE:-cuda}" preset="${WB_STUDIO_PRESET:-gpu}"
      # shellcheck disable=SC2086  # WB_STUDIO_ARGS: options, split on spaces
      env -u DISPLAY -u WAYLAND_DISPLAY QT_QPA_PLATFORM=offscreen QT_PLUGIN_PATH="$s/plugins" \
        FONTCONFIG_FILE="$s/fonts.conf" LD_LIBRARY_PATH="$s/lib" \
        timeout 400 "$s/wetbrush-studio" --device "$dev" --preset "$preset" --view raster --data-dir "$run/data" \
        --demo-stats "$out/studio-stats.json" --demo-screenshot "$out/studio.png" ${WB_STUDIO_ARGS:-} \
        > "$out/studio.txt" 2>&1
      echo "studio ($dev, preset $preset, raster view): exit $?"; grep -E "^demo: [0-9]|latency|canvas:|wrote" "$out/studio.txt" ;;
  esac
done

#!/usr/bin/env bash
# Runs what scripts/bundle-gpu.sh built on a machine with a CUDA GPU: the test suite on the
# CUDA backend, the benchmarks and the example replays, writing logs, stats and pictures to DIR.
#   scripts/gpu-run.sh DIR [tests|bench|replay]...   (all three when none is named)
set -uo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?output directory}"; shift
what="${*:-tests bench replay}"
bin="$here/build-gpu/bin"
export LD_LIBRARY_PATH="$bin${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"
"$bin/wetbrush" devices | tee -a "$out/gpu.txt"
for w in $what; do
  case "$w" in
    tests)
      WB_DEVICE=cuda timeout 400 "$bin/wetbrush_tests" --gtest_brief=1 > "$out/tests-cuda.log" 2>&1
      echo "tests (cuda): exit $?"; grep -E "^\[  (PASSED|FAILED)|FAILED  \]|tests ran" "$out/tests-cuda.log" | head -40 ;;
    bench)
      WB_DEVICE=cuda timeout 300 "$bin/wetbrush_bench" --benchmark_min_time=0.2 \
        --benchmark_out="$out/bench-cuda.json" --benchmark_out_format=json > "$out/bench-cuda.txt" 2>&1
      echo "bench (cuda): exit $?"; grep -E "^BM_" "$out/bench-cuda.txt" ;;
    replay)
      # Every example, painted and saved; press-and-drag also grid-only (Fig. 7).
      for f in "$here"/examples/*.json "$here"/examples/*.txt; do
        ex="$(basename "${f%.*}")"
        timeout 300 "$bin/wetbrush" replay "$f" --device cuda -q -o "$out/$ex.png" --save "$out/$ex.ora" \
          --stats "$out/$ex.json" > "$out/$ex.log" 2>&1
        echo "replay $ex (cuda): exit $?"
      done
      timeout 300 "$bin/wetbrush" replay "$here/examples/press-and-drag.json" --device cuda -q --grid-only \
        -o "$out/press-and-drag-grid-only.png" --save "$out/press-and-drag-grid-only.ora" \
        --stats "$out/press-and-drag-grid-only.json" > "$out/press-and-drag-grid-only.log" 2>&1
      echo "replay press-and-drag --grid-only (cuda): exit $?"
      # Close-ups under a raking light (ridges and bristle streaks).
      for ex in press-and-drag press-and-drag-grid-only cross-wet scumble; do
        [ -f "$out/$ex.ora" ] || continue
        c=512,512; sz=720x400
        [ "$ex" = cross-wet ] && c=520,515 && sz=720x720
        [ "$ex" = scumble ] && c=520,505
        "$bin/wetbrush" render "$out/$ex.ora" --device cuda --center "$c" --size "$sz" --zoom 2 \
          --light -0.8,0.35,0.5 -o "$out/$ex-detail.png" > /dev/null 2>&1
        echo "render $ex detail: exit $?"
      done ;;
  esac
done

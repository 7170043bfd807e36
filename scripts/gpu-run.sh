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
      # The paper's load model: no flow along the bristles.
      timeout 300 "$bin/wetbrush" replay "$here/examples/press-and-drag.json" --device cuda -q \
        --set transfer.wick_rate=0 --set transfer.wick_slide=0 -o "$out/press-and-drag-no-wicking.png" \
        --save "$out/press-and-drag-no-wicking.ora" --stats "$out/press-and-drag-no-wicking.json" \
        > "$out/press-and-drag-no-wicking.log" 2>&1
      echo "replay press-and-drag without wicking (cuda): exit $?"
      # Every painting: a 2:1 close-up under a raking light, centred on the painted region the
      # replay reports, and an oblique view of the whole canvas under the same light.
      for st in "$out"/*.json; do
        ex="$(basename "${st%.json}")"
        [ -f "$out/$ex.ora" ] || continue
        c="$(python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['region']; print('%d,%d' % (r['x0'] + r['width'] // 2, r['y0'] + r['height'] // 2))" "$st")"
        "$bin/wetbrush" render "$out/$ex.ora" --device cuda --center "$c" --size 720x400 --zoom 2 \
          --light -0.8,0.35,0.5 -o "$out/$ex-detail.png" > /dev/null 2>&1
        echo "render $ex detail at $c: exit $?"
        "$bin/wetbrush" render "$out/$ex.ora" --device cuda --camera oblique --elevation 30 \
          --light -0.8,0.35,0.5 -o "$out/$ex-oblique.png" > /dev/null 2>&1
        echo "render $ex oblique: exit $?"
      done ;;
  esac
done

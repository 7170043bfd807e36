#!/usr/bin/env bash
# The hardening checks (docs/RELIABILITY.md):
#  asan: the GoogleTest suite built with AddressSanitizer + UndefinedBehaviorSanitizer (CPU
#        backend, no studio, no benchmarks) in build-asan/, run by CTest as a second
#        configuration, with every fuzz harness replaying its committed corpus (FuzzCorpus.*);
#  fuzz: a libFuzzer run of every harness in tests/fuzz/ (build-fuzz/, clang; WB_FUZZ_SECONDS
#        each, 10 by default) on a copy of its corpus, the Debian packages for it installed first.
# WB_HARDENING=asan (scripts/test.sh's), fuzz or all (the default here).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
what="${WB_HARDENING:-all}"
jobs="$(nproc)"
ok=1

if [ "$what" = all ] || [ "$what" = asan ]; then
  asan="$WB_ROOT/build-asan"
  mkdir -p "$asan"  # its configure log lives inside it, with the other build outputs
  start=$(date +%s)
  cmake -S "$WB_ROOT" -B "$asan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DWB_SANITIZE=ON -DWB_CUDA=OFF \
    -DWB_BUILD_STUDIO=OFF -DWB_PYTHON=OFF -DWB_BUILD_TESTS=ON -DWB_BUILD_BENCH=OFF > "$asan/configure.log" 2>&1 ||
    { cat "$asan/configure.log"; exit 1; }
  cmake --build "$asan" --parallel "$jobs"
  built=$(date +%s)
  # halt_on_error: the first report fails its test; LeakSanitizer is on (ASan's default).
  export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=1:detect_stack_use_after_return=0}"
  export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
  export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"
  # The whole-stroke checks (label long) and the CLI's whole replays (a soak, a bench, a replay
  # with its progress, image or video) run in the main suite only: their kernels and readers run
  # here in the shorter tests, and under the sanitizers they would take most of CI's time.
  if (cd "$asan" && ctest --output-on-failure --parallel "$jobs" --timeout 900 --label-exclude long \
      -E '^Cli\.(SoakReports|ProgressLines|ReplayWritesImage|ReplayWritesATimeLapse|BenchReports|ScumbleKeepsItsBooks)'); then
    echo "hardening: ASan+UBSan suite passed (build $((built - start)) s, tests $(($(date +%s) - built)) s)"
  else
    echo "hardening: ASan+UBSan suite FAILED"
    ok=0
  fi
fi

if [ "$what" = all ] || [ "$what" = fuzz ]; then
  wb_install_deps "${WB_FUZZ_PACKAGES[@]}"
  probe=$(mktemp -d)
  echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' > "$probe/p.cpp"
  if ! command -v clang++ > /dev/null || ! clang++ -fsanitize=fuzzer "$probe/p.cpp" -o "$probe/p" 2> /dev/null; then
    rm -rf "$probe"
    echo "hardening: SKIPPED the fuzz smoke runs: clang++ with libFuzzer is missing (Debian packages clang libclang-rt-dev libomp-dev)"
  else
    rm -rf "$probe"
    fuzz="$WB_ROOT/build-fuzz"
    mkdir -p "$fuzz"
    CC=clang CXX=clang++ cmake -S "$WB_ROOT" -B "$fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DWB_FUZZ=ON \
      -DWB_CUDA=OFF -DWB_BUILD_STUDIO=OFF -DWB_BUILD_TESTS=OFF -DWB_BUILD_BENCH=OFF > "$fuzz/configure.log" 2>&1 ||
      { cat "$fuzz/configure.log"; exit 1; }
    cmake --build "$fuzz" --target fuzzers --parallel "$jobs"
    seconds="${WB_FUZZ_SECONDS:-10}"
    for src in "$WB_ROOT"/tests/fuzz/fuzz_*.cpp; do
      name=$(basename "$src" .cpp)
      harness=${name#fuzz_}
      work=$(mktemp -d)
      log="$fuzz/smoke-$harness.log"
      # One process on one core (no -jobs: with it libFuzzer writes its output to ./fuzz-N.log).
      # New inputs go to the temporary folder (first); the committed corpus is only read.
      if "$fuzz/bin/$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
          -artifact_prefix="$work/" -print_final_stats=1 "$work" "$WB_ROOT/tests/fuzz/corpus/$harness" > "$log" 2>&1; then
        echo "hardening: fuzz $harness: $(sed -n 's/^stat::number_of_executed_units: *//p' "$log") runs in ${seconds} s, no finding"
      else
        echo "hardening: fuzz $harness FOUND A PROBLEM (log: $log, input kept in $fuzz/findings/):"
        mkdir -p "$fuzz/findings"
        cp "$work"/crash-* "$work"/leak-* "$work"/timeout-* "$work"/oom-* "$fuzz/findings/" 2>/dev/null || true
        grep -E "ERROR|SUMMARY" "$log" | head -5
        ok=0
      fi
      rm -rf "$work"
    done
  fi
fi
[ "$ok" -eq 1 ]

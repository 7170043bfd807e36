#!/usr/bin/env bash
# Installs what is missing, checks the install list, builds every product (CLI, tests,
# benchmarks, studio; CPU and, when nvcc exists, CUDA backends), runs every test and ends with a
# summary: the products built and the tests per group (core, long, cli, studio, python). Fails when a test
# fails or a group has no test.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
wb_install_deps
"$WB_ROOT/scripts/check-packages.sh"
wb_build
cd "$WB_BUILD"
# Two test processes share the two cores: OpenMP threads must sleep, not spin, while they wait.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"
junit="$WB_BUILD/ctest-results.xml"
rm -f "$junit"
set +e
ctest --output-on-failure --parallel "$(nproc)" --timeout 900 --output-junit "$junit"
ctest_rc=$?
set -e

# --- hardening: the sanitizer run, corpus replays included (docs/RELIABILITY.md) ---------------
hardening_ok=1
WB_HARDENING="${WB_HARDENING:-asan}" "$WB_ROOT/scripts/hardening.sh" || hardening_ok=0
# --- end hardening --------------------------------------------------------------------------------

# --- summary ---------------------------------------------------------------------------------
echo
echo "== wetbrush test summary =="
ok=1
products=()
for p in wetbrush wetbrush_tests wetbrush_bench wetbrush-studio wetbrush_studio_tests; do
  if [ -x "$WB_BUILD/bin/$p" ]; then products+=("$p"); else echo "MISSING product: bin/$p"; ok=0; fi
done
if compgen -G "$WB_BUILD/bin/wetbrush.*.so" > /dev/null; then products+=("wetbrush (Python module)")
else echo "MISSING product: bin/wetbrush.*.so (the Python module)"; ok=0; fi
cuda=$(sed -n 's/^WB_CUDA:STRING=//p' "$WB_BUILD/CMakeCache.txt")
echo "products built: ${products[*]} (CUDA backend: ${cuda:-OFF})"
# Status of every test case from CTest's JUnit file: name<TAB>status (run, fail, notrun, ...).
statuses=$(sed -n 's/.*<testcase name="\([^"]*\)".*status="\([^"]*\)".*/\1\t\2/p' "$junit" 2>/dev/null |
  sed 's/&lt;/</g; s/&gt;/>/g; s/&quot;/"/g; s/&apos;/'"'"'/g; s/&amp;/\&/g' || true)
total_pass=0 total_fail=0 total_skip=0
for group in core long cli studio python; do
  # One awk over the statuses and the group's names: no reader that stops early, so no SIGPIPE
  # for the writer under pipefail however many tests there are.
  read -r n pass fail skip < <(ctest -N -L "^${group}\$" | sed -n 's/^ *Test *#[0-9]*: //p' |
    awk -F'\t' 'NR == FNR { st[$1] = $2; next }
      $0 != "" { n++; s = ($0 in st) ? st[$0] : ""
        if (s == "run") p++; else if (s == "fail" || s == "") f++; else k++ }
      END { print n + 0, p + 0, f + 0, k + 0 }' <(printf '%s\n' "$statuses") -)
  printf '  %-7s %4d tests: %d passed, %d failed, %d skipped\n' "$group" "$n" "$pass" "$fail" "$skip"
  if [ "$n" -eq 0 ]; then echo "  ERROR: the $group group has no tests"; ok=0; fi
  total_pass=$((total_pass + pass)) total_fail=$((total_fail + fail)) total_skip=$((total_skip + skip))
done
if [ "$ctest_rc" -ne 0 ] || [ "$total_fail" -ne 0 ]; then ok=0; fi
if [ "$hardening_ok" -ne 1 ]; then echo "hardening: the sanitizer run FAILED (above)"; ok=0; fi
echo "summary: $total_pass passed, $total_fail failed, $total_skip skipped"
[ "$ok" -eq 1 ] || { echo "wetbrush: tests FAILED"; exit 1; }

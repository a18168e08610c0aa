#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The whole test suite: install what is missing, then
#  1. build + ctest (Release; the cross builds of the core for Cortex-M7 and
#     M4F are its tests comp_cross_build and comp_stack_m7, label `build`),
#  2. build + ctest with AddressSanitizer and UndefinedBehaviorSanitizer,
#  3. extra checks that exist: static analysis, fuzzing (bounded time), valgrind, the package
#     (fresh-tree install, static and shared, consumer built with find_package
#     and with pkg-config: scripts/install_check.sh, about 30 s) and the SPDX
#     licence line of every source file (scripts/spdx_check.sh), and the host
#     library's layers (scripts/layers.sh), the links between the Markdown pages (scripts/doc_links.py).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
# exported: scripts/valgrind_tests.sh and static_analysis.sh run JOBS at a time
export JOBS=$(nproc)
status=0

echo "== build and test (Release)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$JOBS" 2>&1 | grep -E 'warning|error' || true
cmake --build build -j"$JOBS" >/dev/null
ctest --test-dir build --output-on-failure -j"$JOBS" || status=1

# the studies (label `study`: simulated robots by the dozen, every report read back) ran above; the sanitizers
# watch the code paths, which the other tests take (DESIGN.md, "Tests")
echo "== build and test with ASan + UBSan (labels study, timing and build left out)"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DRCAL_SANITIZE=ON >/dev/null
cmake --build build-asan -j"$JOBS" >/dev/null
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j"$JOBS" -LE '^(study|timing|build)$' || status=1

# fuzz/run.sh: every target 12 s from its committed corpus (the corpus is the regression; new finds are a
# release's longer run), two at a time (the two cores of the CI machine; 21 targets; FUZZ_SECONDS and FUZZ_JOBS
# set from outside win: docs/release.md)
export FUZZ_SECONDS=${FUZZ_SECONDS:-12} FUZZ_JOBS=${FUZZ_JOBS:-2}
for extra in scripts/static_analysis.sh fuzz/run.sh scripts/valgrind_tests.sh \
  scripts/install_check.sh scripts/spdx_check.sh scripts/layers.sh scripts/doc_links.py; do
  if [ -x "$extra" ]; then
    echo "== $extra"
    "$extra" || status=1
  fi
done

if [ $status -eq 0 ]; then echo "ALL CHECKS PASSED"; else echo "SOME CHECKS FAILED"; fi
exit $status

#!/usr/bin/env bash
# The test suite under AddressSanitizer + UndefinedBehaviorSanitizer (issue 8), after the normal run
# (.ci/run). Usage: bash packaging/run-sanitizer-tests.sh   (GROUNDPLAN_SANITIZE_LABELS_EXCLUDE to skip labels)
#
# Two ctest passes over one -DGROUNDPLAN_SANITIZE=ON build:
#  1. everything but e2e, leak detection on: gtest executables are linked with the sanitizers;
#  2. e2e (pytest): Python loads our plugin with dlopen, and ASan must be the first library of the
#     process, so libasan/libubsan are LD_PRELOADed into python3, ogr2ogr and ogrinfo. Leak detection
#     is off there: Python and GDAL keep memory to exit by design, which LSan would report as ours.
#     The CLI and the plugin still run fully instrumented (heap, stack, UB checks).
set -euo pipefail
cd "$(dirname "$0")/.."
bash packaging/install-deps.sh
build=${GROUNDPLAN_SANITIZE_BUILD_DIR:-build-asan}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DGROUNDPLAN_SANITIZE=ON -DGROUNDPLAN_BUILD_BENCH=OFF \
  -DGROUNDPLAN_CUDA=OFF >/dev/null
cmake --build "$build" -j"$(nproc)"

export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
exclude=${GROUNDPLAN_SANITIZE_LABELS_EXCLUDE:-}
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
  ctest --test-dir "$build" --output-on-failure -j"$(nproc)" --timeout 1800 -LE "e2e${exclude:+|$exclude}"

preload="$(gcc -print-file-name=libasan.so):$(gcc -print-file-name=libubsan.so)"
LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
  ctest --test-dir "$build" --output-on-failure --timeout 1800 -L e2e

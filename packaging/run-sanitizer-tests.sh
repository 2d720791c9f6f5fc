#!/usr/bin/env bash
# The test suite under AddressSanitizer + UndefinedBehaviorSanitizer (issue 8), after the normal run
# (.ci/run). Usage: bash packaging/run-sanitizer-tests.sh   (GROUNDPLAN_SANITIZE_LABELS_EXCLUDE to skip labels)
#
# Two passes over one -DGROUNDPLAN_SANITIZE=ON build (gcc):
#  1. ctest, everything but e2e, leak detection on: the gtest executables are linked with the sanitizers;
#  2. e2e through pytest: Python loads our plugin with dlopen, and ASan must be the first library of the
#     process, so libasan/libubsan are LD_PRELOADed into python3 and what it runs (the CLI, ogr2ogr).
#     Leak detection is off there: Python and GDAL keep memory to exit by design, which LSan would
#     report as ours. The CLI and the plugin still run fully instrumented (heap, stack, UB checks).
#     CI runs test_bad_input.py (the corpus, hostile input and every real sample through the CLI:
#     25 s) and the -limit/-where cases of test_gpkg_writers.py; the whole e2e under sanitizers takes ~10 min on 2 cores (GROUNDPLAN_SANITIZE_E2E=all).
#     test_package.py is never run here: cpack of a sanitizer build under LD_PRELOAD passes 10 minutes
#     and tests packaging, not memory safety.
#  3. the Python module's tests (tests/python, where the module was built), the same way as 2: the
#     extension is loaded into python3, so it cannot run in pass 1 (ASan would abort: not first in the process).
set -euo pipefail
cd "$(dirname "$0")/.."
bash packaging/install-deps.sh
build=${GROUNDPLAN_SANITIZE_BUILD_DIR:-build-asan}
source packaging/ccache-flags.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DGROUNDPLAN_SANITIZE=ON -DGROUNDPLAN_BUILD_BENCH=OFF \
  -DGROUNDPLAN_CUDA=OFF "${ccache_flags[@]}" >/dev/null
cmake --build "$build" -j"$(nproc)"

export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
exclude=${GROUNDPLAN_SANITIZE_LABELS_EXCLUDE:-}
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
  ctest --test-dir "$build" --output-on-failure -j"$(nproc)" --timeout 1800 -LE "e2e|python${exclude:+|$exclude}"

preload="$(gcc -print-file-name=libasan.so):$(gcc -print-file-name=libubsan.so)"
if [ "${GROUNDPLAN_SANITIZE_E2E:-bad-input}" = all ]; then
  e2e=(tests/e2e --ignore=tests/e2e/test_package.py)
else
  # and the CLI's writer stopped early (ogr2ogr -limit: the layers once outlived the SRS they hold)
  e2e=(tests/e2e/test_bad_input.py "tests/e2e/test_gpkg_writers.py::test_options_across_features_keep_one_writer")
fi
GROUNDPLAN_BIN="$PWD/$build/bin/groundplan" GDAL_DRIVER_PATH="$PWD/$build/gdalplugins" GROUNDPLAN_SOURCE_DIR="$PWD" \
  GROUNDPLAN_BUILD_DIR="$PWD/$build" LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
  /usr/bin/python3 -m pytest -q -p no:cacheprovider "${e2e[@]}"
if [ -d "$build/python/groundplan" ]; then
  GROUNDPLAN_BIN="$PWD/$build/bin/groundplan" GDAL_DRIVER_PATH="$PWD/$build/gdalplugins" GROUNDPLAN_SOURCE_DIR="$PWD" \
    GROUNDPLAN_BUILD_DIR="$PWD/$build" PYTHONPATH="$PWD/$build/python" LD_PRELOAD="$preload" \
    ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python
fi

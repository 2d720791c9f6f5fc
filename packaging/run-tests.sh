#!/usr/bin/env bash
# Sets up (dependencies, build) and runs the whole test suite. Usage: bash packaging/run-tests.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash packaging/install-deps.sh
build=${GROUNDPLAN_BUILD_DIR:-build}
source packaging/ccache-flags.sh
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DGROUNDPLAN_CUDA=${GROUNDPLAN_CUDA:-AUTO} "${ccache_flags[@]}" >/dev/null
cmake --build "$build" -j"$(nproc)"
# Samples that may not be redistributed (tests/data/README.md): tests labelled thirdparty-data use them where found
# and are skipped, one line each, where not.
thirdparty=${GROUNDPLAN_SHARED_DATA_DIR:-$(sed -n 's/^GROUNDPLAN_SHARED_DATA_DIR:PATH=//p' "$build/CMakeCache.txt")}
if [ -d "$thirdparty" ]; then
  echo "third-party samples: $thirdparty (ctest label thirdparty-data runs)"
else
  echo "third-party samples: not found at $thirdparty; the tests labelled thirdparty-data are skipped (GROUNDPLAN_SHARED_DATA_DIR)"
fi
status=0
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" --timeout 900 || status=$?
# ctest lists skipped tests without their reason: one line each, from the log (gtest's GTEST_SKIP message,
# the e2e runner's "SKIPPED: ..." line).
awk '/^[0-9]+\/[0-9]+ Test: / { name = substr($0, index($0, ": ") + 2) }
     reason { print "skipped: " name ": " $0; reason = 0 }
     /: Skipped$/ { reason = 1 }
     /^SKIPPED: / { print "skipped: " name ": " substr($0, 10) }' "$build/Testing/Temporary/LastTest.log"
exit "$status"

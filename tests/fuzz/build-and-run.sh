#!/usr/bin/env bash
# CI's short fuzz run (issue 8): builds the libFuzzer targets with clang in build-fuzz (only what they
# link: core, gis, geosref) and runs each for SECONDS (default 10). Usage: tests/fuzz/build-and-run.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${GROUNDPLAN_FUZZ_BUILD_DIR:-build-fuzz}
source packaging/ccache-flags.sh
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGROUNDPLAN_CUDA=OFF \
  -DGROUNDPLAN_FUZZ=ON -DGROUNDPLAN_BUILD_BENCH=OFF "${ccache_flags[@]}" >/dev/null
cmake --build "$build" -j"$(nproc)" --target fuzz_citygml fuzz_srs_name fuzz_coordinates fuzz_union fuzz_read_any fuzz_lod
bash tests/fuzz/run-fuzz.sh "$build" "${1:-10}" "$build/fuzz-work"

#!/usr/bin/env bash
# Sets up (dependencies, build) and runs the whole test suite. Usage: bash packaging/run-tests.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash packaging/install-deps.sh
build=${GROUNDPLAN_BUILD_DIR:-build}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DGROUNDPLAN_CUDA=${GROUNDPLAN_CUDA:-AUTO} >/dev/null
cmake --build "$build" -j"$(nproc)"
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" --timeout 900

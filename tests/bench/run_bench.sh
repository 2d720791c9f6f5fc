#!/bin/sh
# Runs the union benchmark matrix (issue 3) and prints one line per (engine, size) plus ratios.
#   tests/bench/run_bench.sh BUILD_DIR [SIZES] [GEOS_MAX]
# SIZES defaults to "1000 6000 60000 1000000"; GEOS is not run above GEOS_MAX footprints
# (default 60000; its time grows faster than linearly: see RESULTS.md for the extrapolation).
# Example (RESULTS.md): tests/bench/run_bench.sh build "1000 6000 60000 200000 1000000" 200000
set -eu
build=${1:-build}
sizes=${2:-"1000 6000 60000 1000000"}
geos_max=${3:-60000}
bin="$build/bin/bench_union"
runs_for() { if [ "$1" -ge 1000000 ]; then echo 3; elif [ "$1" -ge 60000 ]; then echo 5; else echo 7; fi; }
echo "engine n runs median_wall_s min_wall_s max_wall_s median_cpu_s plans peak_rss_mib input_rss_mib min_cpu_s"
for n in $sizes; do
  r=$(runs_for "$n")
  "$bin" --n "$n" --engine ours --runs "$r"
  "$bin" --n "$n" --engine ours --runs "$r" --threads 1 | sed 's/^ours/ours_1thread/'
  if [ "$n" -le "$geos_max" ]; then
    g=$([ "$n" -ge 200000 ] && echo 1 || { [ "$n" -ge 60000 ] && echo 3 || echo 5; })
    "$bin" --n "$n" --engine geos --runs "$g"
    "$bin" --n "$n" --engine ours --runs "$r" --coverage | sed 's/^ours/ours_coverage_input/'
    "$bin" --n "$n" --engine coverage --runs "$g" --coverage
  fi
done

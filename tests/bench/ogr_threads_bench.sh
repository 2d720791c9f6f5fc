#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Issue 22 benchmark: one GeoPackage of N footprints (gen_footprints_gpkg.py, through GDAL) read by groundplan on
# 1 thread, on T threads without feature ranges (--read-range-features -1: only footprints and the union are
# parallel), and on T threads in feature ranges (one dataset handle per range). Medians of RUNS runs: wall
# seconds of the whole run and the reading stage (--stats timings_s.read); checks that the outputs are the same.
# Usage: tests/bench/ogr_threads_bench.sh BUILD_DIR [N=1000000] [RUNS=3] [T=2] [WORK_DIR=/tmp/groundplan-ogr-bench]
set -euo pipefail
build=${1:?build dir}
n=${2:-1000000}
runs=${3:-3}
threads=${4:-2}
work=${5:-/tmp/groundplan-ogr-bench}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
src="$work/footprints_$n.gpkg"
[ -f "$src" ] || /usr/bin/python3 "$here/gen_footprints_gpkg.py" "$src" "$n"
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
read_s() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['timings_s']['read'])" "$1"; }
echo "date=$(date -u +%FT%TZ) host=$(lscpu | sed -n 's/^Model name: *//p') cores=$(nproc) load=$(cut -d' ' -f1-3 /proc/loadavg)"
for mode in "1 0" "$threads -1" "$threads 0"; do
  set -- $mode
  walls=(); reads=()
  for ((r = 0; r < runs; r++)); do
    rm -rf "$work/out_$1_$2"
    t0=$(date +%s.%N)
    "$build/bin/groundplan" -q --threads "$1" --read-range-features "$2" --stats "$work/stats_$1_$2.json" \
      -f CSV -lco GEOMETRY=AS_WKT "$work/out_$1_$2" "$src" ground_plans problems
    walls+=("$(python3 -c 'import sys; print(round(float(sys.argv[1]) - float(sys.argv[2]), 3))' "$(date +%s.%N)" "$t0")")
    reads+=("$(read_s "$work/stats_$1_$2.json")")
  done
  chunks=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['reading']; print(r['chunks'], r['read_whole'])" "$work/stats_$1_$2.json")
  echo "threads=$1 read_range_features=$2 wall_median_s=$(printf '%s\n' "${walls[@]}" | median) read_median_s=$(printf '%s\n' "${reads[@]}" | median) ranges/read_whole=$chunks"
  echo "  wall runs: ${walls[*]}  read runs: ${reads[*]}"
done
for l in ground_plans problems; do
  cmp -s "$work/out_1_0/$l.csv" "$work/out_${threads}_0/$l.csv" && echo "$l.csv: same on 1 and $threads threads" \
    || { echo "$l.csv DIFFERS between 1 and $threads threads"; exit 1; }
done

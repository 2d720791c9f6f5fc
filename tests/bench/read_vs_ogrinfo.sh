#!/usr/bin/env bash
# MB/s of our reader (file -> meshes, tests/bench/read_any_bench) against `ogrinfo -al -q` with GDAL's own
# GML driver on the same file, medians of N runs each, in one run (issue 6). The yardstick only: GDAL's GML
# driver builds features (no CityGML solids, see DESIGN.md), we build meshes.
# Usage: tests/bench/read_vs_ogrinfo.sh [BUILD_DIR=build] [FILE...]   (default: the largest real CityGML samples)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
shift || true
files=("$@")
if [ ${#files[@]} -eq 0 ]; then
  mapfile -t files < <(find "$here/../shared/data" "$here/sample_data" \( -name '*.gml' -o -name '*.citygml' \) \
                         -printf '%s %p\n' 2>/dev/null | sort -rn | awk '{print $2}' | head -2)
fi
runs=${RUNS:-5}
bench="$build/tests/bench/read_any_bench"
[ -x "$bench" ] || bench="$build/bin/read_any_bench"
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
echo "machine: $(lscpu | grep 'Model name' | sed 's/ \+/ /g'), $(nproc) cores (shared, noisy)"
echo "gdal: $(gdal-config --version)"
# ogrinfo's times include starting a process and registering drivers: its floor, for reference.
floor=()
for _ in $(seq "$runs"); do
  t0=$(date +%s.%N); ogrinfo --version > /dev/null; t1=$(date +%s.%N)
  floor+=("$(echo "$t1 - $t0" | bc -l)")
done
printf 'ogrinfo --version (process start + driver registration): %.4f s median\n' "$(printf '%s\n' "${floor[@]}" | median)"
for f in "${files[@]}"; do
  mb=$(awk -v b="$(stat -c %s "$f")" 'BEGIN {printf "%.3f", b / 1e6}')
  ours=$("$bench" "$f" "$runs")
  ours_s=$(echo "$ours" | awk '/^median_s/ {print $2}')
  # ogrinfo: GML driver, no .gfs written beside the input (each run scans the schema again, as ours does).
  times=()
  for _ in $(seq "$runs"); do
    t0=$(date +%s.%N)
    ogrinfo -ro -al -q -oo WRITE_GFS=NO "$f" > /dev/null 2>&1 || true
    t1=$(date +%s.%N)
    times+=("$(echo "$t1 - $t0" | bc -l)")
  done
  ogr_s=$(printf '%s\n' "${times[@]}" | median)
  printf '%s (%s MB): ours %.4f s = %.1f MB/s (%s meshes); ogrinfo -al -q %.4f s = %.1f MB/s; ratio %.1fx\n' \
    "$(basename "$f")" "$mb" "$ours_s" "$(echo "$mb / $ours_s" | bc -l)" "$(echo "$ours" | awk '/^meshes/ {print $2}')" \
    "$ogr_s" "$(echo "$mb / $ogr_s" | bc -l)" "$(echo "$ogr_s / $ours_s" | bc -l)"
done

#!/bin/bash
# Issue 15's memory goal at the size it names, on the 16-core GPU host: a generated tiled city of TX x TY tiles of
# K x K copies of the Lorup LoD1 tile (80 city objects, 104 buildings and parts a copy; 25 25 10 = 625 tiles,
# 6,500,000 buildings, 49 GB),
# written by 16 generator processes side by side (gen_tiled_city.py --rows), then tiles_memory_bench.sh with
# COMPARE=0: peak RSS, CPU and wall of one process (--tiles off) and of the tiled run (--tiles on), the plans
# discarded (/vsistdout/) and the two runs' counts compared. The bundle comes from tests/gpu/pack_cli.sh.
# Usage, from the repository root: tests/bench/country_memory_on_device.sh BUNDLE [TX TY K] [THREADS]
set -u
BUNDLE=${1:?BUNDLE}; TX=${2:-25}; TY=${3:-25}; K=${4:-10}; THREADS=${5:-16}
W=/tmp/gp-country
source "$(dirname "$0")/../gpu/unpack_bundle.sh"
echo "== machine"; date -u; nproc; free -g | head -2; df -h /tmp | tail -1
echo "== city: $TX x $TY tiles of $K x $K copies"
s=$(date +%s)
for p in $(seq 0 15); do
  python3 tests/bench/gen_tiled_city.py "$W/city" "$TX" "$TY" "$K" -3 --rows=$(( p * TY / 16 )):$(( (p + 1) * TY / 16 )) > /dev/null &
done
wait
echo "  $(ls "$W/city" | wc -l) files, $(du -sh "$W/city" | cut -f1), made in $(( $(date +%s) - s )) s"; df -h /tmp | tail -1
COMPARE=0 GROUNDPLAN_BIN=$G/bin/groundplan bash tests/bench/tiles_memory_bench.sh "$W/city" "$THREADS"
rm -rf "$W/city"

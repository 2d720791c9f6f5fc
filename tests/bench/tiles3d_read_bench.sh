#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# 3D Tiles reading against CityGML reading of the same city (not run in CI; figures in RESULTS.md).
# The city: the Lower Saxony LoD1 tile (80 buildings) repeated on an N x N grid. As CityGML: gen_big_citygml.py's
# shifted copies in one file. As 3D Tiles: tests/data/3dtiles/levels/all.b3dm (the same 80 buildings, made from
# that tile by make_tilesets.py) as the content of N x N tiles, each translated in the east-north-up frame. Both
# are read by the CLI into plans; the medians of 3 runs and the ratio in buildings per second are printed.
# Usage (repository root, after a Release build): tests/bench/tiles3d_read_bench.sh [N] [THREADS]
set -euo pipefail
N=${1:-20}
THREADS=${2:-$(nproc)}
BIN=${GROUNDPLAN_BIN:-build/bin/groundplan}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
SRC=tests/data/3dtiles
python3 - "$N" "$TMP" "$SRC" <<'EOF'
import json, shutil, sys
n, tmp, src = int(sys.argv[1]), sys.argv[2], sys.argv[3]
root = json.load(open(f"{src}/levels/replace.json"))["root"]
step = 2100.0  # metres: the tile is ~1.9 km across
children = []
for i in range(n):
    for j in range(n):
        children.append({"boundingVolume": {"sphere": [0, 0, 0, 2000]}, "geometricError": 0,
                         "transform": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, i * step, j * step, 0, 1],
                         "content": {"uri": "all.b3dm"}})
ts = {"asset": {"version": "1.0"}, "geometricError": 1000,
      "root": {"boundingVolume": {"sphere": [0, 0, 0, 1e5]}, "geometricError": 1000, "refine": "ADD",
               "transform": root["transform"], "children": children}}
import os
os.makedirs(f"{tmp}/tiles")
json.dump(ts, open(f"{tmp}/tiles/tileset.json", "w"))
shutil.copy(f"{src}/levels/all.b3dm", f"{tmp}/tiles/all.b3dm")
EOF
# The CityGML of about the same number of copies: gen_big_citygml.py sizes by MB (the tile is 0.8 MB).
python3 tests/bench/gen_big_citygml.py "$TMP/city.gml" $(( N * N * 795879 / 1000000 + 1 )) \
  ../shared/data/citygml1-niedersachsen-lod1-4tiles/LoD1_24065862_2_2021-01-25.gml >/dev/null
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
run() {  # input -> "median seconds" "buildings" in $TMP/result
  : > "$TMP/times"
  : > "$TMP/reads"
  for k in 1 2 3; do
    local t0 t1
    t0=$(date +%s.%N)
    "$BIN" --threads "$THREADS" -f GPKG "$TMP/out.gpkg" "$1" -overwrite >"$TMP/log" 2>&1
    t1=$(date +%s.%N)
    echo "$t1 - $t0" | bc >> "$TMP/times"
    grep -o '(read [0-9.]* s' "$TMP/log" | grep -o '[0-9.]*' >> "$TMP/reads"
  done
  echo "$(median < "$TMP/times") $(grep -o 'read [0-9,]* buildings' "$TMP/log" | tr -d , | grep -o '[0-9]*') $(median < "$TMP/reads")" > "$TMP/result"
  cat "$TMP/log" >&2
  : > "$TMP/reads"
}
run "$TMP/tiles/tileset.json"
read -r ts tb tr < "$TMP/result"
run "$TMP/city.gml"
read -r gs gb gr < "$TMP/result"
tiles_mb=$(du -cb "$TMP/tiles/all.b3dm" | tail -1 | awk -v n=$((N * N)) '{print $1 * n / 1e6}')
gml_mb=$(du -b "$TMP/city.gml" | awk '{print $1 / 1e6}')
echo "threads $THREADS, $((N * N)) tiles"
echo "3D Tiles: $tb buildings, $tiles_mb MB of contents; run median $ts s; reading (CLI's \"read\") median $tr s: $(echo "$tb / $tr" | bc) buildings/s, $(echo "scale=1; $tiles_mb / $tr" | bc) MB/s"
echo "CityGML:  $gb buildings, $gml_mb MB; run median $gs s; reading median $gr s: $(echo "$gb / $gr" | bc) buildings/s, $(echo "scale=1; $gml_mb / $gr" | bc) MB/s"
# The same city both ways counted in copies of the tile (CityGML's "buildings" count its BuildingParts too).
gc=$(grep -c '<bldg:Building ' "$TMP/city.gml")
echo "copies of the tile read per second: 3D Tiles $(echo "scale=1; $N * $N / $tr" | bc), CityGML $(echo "scale=1; $gc / 80 / $gr" | bc)"
echo "ratio of reading speeds (3D Tiles / CityGML, copies/s): $(echo "scale=2; ($N * $N / $tr) / ($gc / 80 / $gr)" | bc)"

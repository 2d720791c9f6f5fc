#!/bin/bash
# The GeoPackage's packed spatial index at country-tile scale, on the 16-core GPU host: a generated LoD1 city of
# CITY_MB (default 7,500 MB, ~609k plans) written by this build and by another packed beside it (AB_BIN, a path
# given to PACK_EXTRA_BINS of tests/gpu/pack_cli.sh), alternated; per run the wall time, --stats' stages and the
# index's read / write / commit, and the md5 of the index's rowid table (the same index whatever the build).
# Usage, from the repository root: AB_BIN=groundplan_old tests/bench/gpkg_index_on_device.sh BUNDLE [CITY_MB] [ROUNDS]
set -u
BUNDLE=${1:?BUNDLE}; MB=${2:-7500}; ROUNDS=${3:-3}
W=/tmp/gp-index
source "$(dirname "$0")/../gpu/unpack_bundle.sh"
python3 tests/bench/gen_big_citygml.py "$W/big.gml" "$MB" | tail -1
cat "$W/big.gml" > /dev/null
for i in $(seq "$ROUNDS"); do
  for b in ${AB_BIN:-} groundplan; do
    [ -x "$G/bin/$b" ] || { echo "$b: not in the bundle"; continue; }
    rm -f "$W/o.gpkg"
    /usr/bin/time -f "%e" -o "$W/t" "$G/bin/$b" -q --device cpu --stats "$W/s.json" -f GPKG "$W/o.gpkg" "$W/big.gml"
    python3 - "$b" "$W/s.json" "$(cat "$W/t")" "$W/o.gpkg" <<'PY'
import hashlib, json, sqlite3, sys
b, f, wall, gpkg = sys.argv[1:5]
d = json.load(open(f)); t = d["timings_s"]; si = d["spatial_index"]
rows = sqlite3.connect(gpkg).execute("SELECT rowid, nodeno FROM rtree_ground_plans_geom_rowid ORDER BY 1").fetchall()
print("%-15s wall %5.2f | read %5.2f union %5.2f write %5.2f | index %4.2f (read %4.2f write %4.2f commit %4.2f) | "
      "plans %d | rowid md5 %s" % (b, float(wall), t["read"], t["union"], t["write"], t["spatial_index"], si["read_s"],
      si["write_s"], si["commit_s"], d["counts"]["ground_plans"], hashlib.md5(repr(rows).encode()).hexdigest()[:12]))
PY
  done
done

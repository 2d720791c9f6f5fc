#!/bin/bash
# The GeoPackage written by several writers (driver/output/gpkg_slices.h, issue 14) against one writer, on the
# 16-core GPU host (no GDAL there: the CLI comes packed by tests/gpu/pack_cli.sh). A generated LoD1 city
# (gen_big_citygml.py) as one file and as 16 tiles (--tiles off: one process), all cores, alternated rounds:
#   slices  the default (one writer per 8,192 plans, at most 16);
#   one     the same with -dim XY: an ogr2ogr option the slices do not take, so one writer as before this
#           change, and the same output (the plans are 2D already);
# then --threads 1 for the speed-up, and a check that both files hold the same rows, extent, count and index.
# Usage, from the repository root: tests/bench/gpkg_writers_on_device.sh BUNDLE.tar.xz [CITY_MB] [ROUNDS]
set -u
BUNDLE=${1:?BUNDLE}; MB=${2:-1500}; ROUNDS=${3:-3}
OUT=${OUT:-gpkg-writers-out}; mkdir -p "$OUT"
exec > >(tee "$OUT/gpkg_writers.log") 2>&1
W=/tmp/gp-writers
source "$(dirname "$0")/../gpu/unpack_bundle.sh"
echo "== machine"; date -u; nproc; lscpu | grep -E "Model name|^Thread|^Core|^Socket"; free -g | head -2

gp() {  # NAME ARGS... : one run, one line
  local name=$1; shift
  rm -rf "$W/$name.gpkg"
  /usr/bin/time -f "%e %U %S %M" -o "$W/$name.time" $G/bin/groundplan -q --device cpu --stats "$W/$name.json" \
    -f GPKG "$W/$name.gpkg" "$@" || { echo "$name: exit $?"; return; }
  python3 - "$name" "$W/$name.json" "$W/$name.time" <<'PY'
import json, sys
name, stats, tm = sys.argv[1:4]
d = json.load(open(stats)); t = d["timings_s"]; w = d.get("writer", {})
wall, user, sys_, rss = open(tm).read().split()[-4:]
print("%-16s wall %6.2f s | read %5.2f union %5.2f write %5.2f (slices %s append %s index %.2f) | writers %s | "
      "cpu %6.1f s | rss %5.0f MiB | plans %s" % (name, float(wall), t["read"], t["union"], t["write"],
      "%.2f" % w["slices_s"] if "slices_s" in w else "-", "%.2f" % w["append_s"] if "append_s" in w else "-",
      t.get("spatial_index", 0), w.get("writers"), float(user) + float(sys_), int(rss) / 1024,
      d["counts"]["ground_plans"]))
PY
}

echo "== city: gen_big_citygml.py $MB MB, and 16 tiles of it"
python3 tests/bench/gen_big_citygml.py "$W/city.gml" "$MB" | tail -1
python3 tests/bench/split_citygml_tiles.py "$W/city.gml" 16 "$W/tiles" | tail -1
cat "$W/city.gml" "$W"/tiles/* > /dev/null

echo "== one file and 16 tiles, all cores, alternated"
for i in $(seq 1 "$ROUNDS"); do
  gp "file_slices_$i" "$W/city.gml"
  gp "file_one_$i" "$W/city.gml" -dim XY
  gp "tiles_slices_$i" "$W/tiles" --tiles off
  gp "tiles_one_$i" "$W/tiles" --tiles off -dim XY
done
gp file_t1 "$W/city.gml" --threads 1

echo "== the same file content"
python3 - "$W/file_slices_1.gpkg" "$W/file_one_1.gpkg" <<'PY'
import sqlite3, sys
a, b = (sqlite3.connect(f) for f in sys.argv[1:3])
for q in ["SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY type, name",
          "SELECT table_name, min_x, min_y, max_x, max_y FROM gpkg_contents", "SELECT * FROM gpkg_ogr_contents",
          "SELECT * FROM ground_plans ORDER BY fid", "SELECT * FROM rtree_ground_plans_geom ORDER BY id"]:
    print("%-70s equal: %s" % (q[:70], list(a.execute(q)) == list(b.execute(q))))
print("integrity:", a.execute("PRAGMA integrity_check").fetchone()[0],
      "| rtreecheck:", a.execute("SELECT rtreecheck('rtree_ground_plans_geom')").fetchone()[0])
PY

#!/bin/bash
# Issue 14's benchmark on the 16-core GPU host (no GDAL there: the CLI and ogr2ogr come packed by
# tests/gpu/pack_cli.sh with PACK_EXTRA_BINS=ogr2ogr). A generated LoD1 city (tests/bench/gen_big_citygml.py)
# as one file and as 16 tiles of the same buildings (split_citygml_tiles.py): end to end with all cores
# and with --threads 1, reading scaling over 1..16 threads, the GeoPackage writer against ogr2ogr copying
# the same features, CPU time and peak RSS (/usr/bin/time), and the outputs' hashes (the same whatever
# the threads or the cut). Usage, from the repository root:
#   [SECTIONS="same e2e index alloc copy scaling xml bench ab stream"] tests/bench/city_scale_on_device.sh BUNDLE.tar.xz [CITY_MB] [BIG_CITY_MB]
# SECTIONS picks what runs (default: all but xml and bench); "xml" times the CityGML reader in memory (pugixml,
# the default) against streamed through expat (--config GROUNDPLAN_XML_IN_MEMORY_BYTES 0) in alternated rounds,
# "bench" runs citygml_read_bench (packed with PACK_EXTRA_BINS) on two real samples and a 60 MB generated city;
# "ab" alternates this build with another CLI packed beside it (AB_BIN=groundplan_before, a path given to
# PACK_EXTRA_BINS) on the same inputs, and compares their outputs; "stream" alternates the GeoPackage written while
# the union goes on with the same build writing after it, and compares the files' tables.
set -u
BUNDLE=${1:?BUNDLE}; MB=${2:-1500}; BIG_MB=${3:-0}
SECTIONS=${SECTIONS:-"same e2e index alloc copy scaling"}
want() { [[ " $SECTIONS " == *" $1 "* ]]; }
OUT=${OUT:-city-scale-out}; mkdir -p "$OUT"
exec > >(tee "$OUT/city_scale.log") 2>&1
W=/tmp/gp-city
source "$(dirname "$0")/../gpu/unpack_bundle.sh"
echo "== machine"; date -u; nproc; lscpu | grep -E "Model name|^Thread|^Core|^Socket|^NUMA node\(s\)|MHz"; free -g | head -2
$G/bin/groundplan --version || { ldd $G/bin/groundplan | grep "not found"; exit 1; }

line() {  # NAME STATS.json TIME.txt -> one line
  python3 - "$@" <<'PY'
import json, sys
name, stats, tm = sys.argv[1:4]
d = json.load(open(stats)); t = d["timings_s"]; r = d.get("reading", {})
wall, user, sys_, rss = open(tm).read().split()[-4:]
si = d.get("spatial_index")
idx = " [index read %.2f write %.2f commit %.2f]" % (si["read_s"], si["write_s"], si["commit_s"]) if si else ""
print("%-22s wall %6.2f s | read %6.2f fp %5.2f blocks %5.2f union %5.2f write %5.2f (index %4.2f) | cpu %6.1f s "
      "(sys %5.1f) | rss %5.0f MiB | threads %s chunked %s/%s files, %s chunks | plans %s%s" % (name, float(wall),
      t["read"], t["footprints"], t["blocks"], t["union"], t["write"], t.get("spatial_index", 0),
      float(user) + float(sys_), float(sys_), int(rss) / 1024, r.get("threads"), r.get("files_chunked"),
      r.get("files"), r.get("chunks"), d["counts"]["ground_plans"], idx))
PY
}
gp() {  # NAME ARGS... : one run, its line
  local name=$1; shift
  rm -rf "$W/$name.gpkg" "$W/$name.csv"
  /usr/bin/time -f "%e %U %S %M" -o "$W/$name.time" $G/bin/${GP_BIN:-groundplan} -q --device cpu --stats "$W/$name.json" "$@"
  local rc=$?
  [ $rc = 0 ] && line "$name" "$W/$name.json" "$W/$name.time" || echo "$name: exit $rc"
}

echo "== city: gen_big_citygml.py $MB MB, split into 16 tiles"
s=$(date +%s); python3 tests/bench/gen_big_citygml.py "$W/city.gml" "$MB" | tail -1
python3 tests/bench/split_citygml_tiles.py "$W/city.gml" 16 "$W/tiles" | tail -1; echo "  made in $(( $(date +%s) - s )) s"
cat "$W/city.gml" > /dev/null; cat "$W"/tiles/* > /dev/null  # in the page cache, as for every run below

if want same; then
echo "== same output whatever the threads, the cut and the XML parser (ground_plans as CSV WKT)"
gp csv_t1 -f CSV -lco GEOMETRY=AS_WKT "$W/csv_t1.csv" "$W/city.gml" --threads 1
gp csv_t16 -f CSV -lco GEOMETRY=AS_WKT "$W/csv_t16.csv" "$W/city.gml"
gp csv_tiles -f CSV -lco GEOMETRY=AS_WKT "$W/csv_tiles.csv" "$W/tiles"
# From 1 GiB in 2+ files the folder goes through the tiled run by default (issue 15: same plans, final ones
# first, rings may start elsewhere); --tiles off is the one-process run, byte-identical to the single file.
gp csv_tiles_off -f CSV -lco GEOMETRY=AS_WKT "$W/csv_tiles_off.csv" "$W/tiles" --tiles off
gp csv_t16_expat -f CSV -lco GEOMETRY=AS_WKT "$W/csv_t16_expat.csv" "$W/city.gml" --config GROUNDPLAN_XML_IN_MEMORY_BYTES 0
md5sum "$W"/csv_t1.csv "$W"/csv_t16.csv "$W"/csv_tiles.csv "$W"/csv_tiles_off.csv "$W"/csv_t16_expat.csv | sed "s#$W/##"
python3 - "$W/csv_t1.csv" "$W/csv_tiles.csv" <<'PY'
import sys
a, b = (sorted(open(f).read().splitlines()[1:]) for f in sys.argv[1:3])
print("tiled run: %d plans, one process: %d; as sorted lines equal: %s" % (len(b), len(a), a == b))
PY
fi

if want xml; then
  echo "== CityGML in memory (pugixml, default) against streamed (expat), alternated rounds, all cores and one"
  for i in 1 2 3; do
    gp "mem_file_$i" -f GPKG "$W/mem_file_$i.gpkg" "$W/city.gml"
    gp "expat_file_$i" -f GPKG "$W/expat_file_$i.gpkg" "$W/city.gml" --config GROUNDPLAN_XML_IN_MEMORY_BYTES 0
    gp "mem_tiles_$i" -f GPKG "$W/mem_tiles_$i.gpkg" "$W/tiles" --tiles off
    gp "expat_tiles_$i" -f GPKG "$W/expat_tiles_$i.gpkg" "$W/tiles" --tiles off --config GROUNDPLAN_XML_IN_MEMORY_BYTES 0
  done
  gp mem_file_t1 -f GPKG "$W/mem_file_t1.gpkg" "$W/city.gml" --threads 1
  gp expat_file_t1 -f GPKG "$W/expat_file_t1.gpkg" "$W/city.gml" --threads 1 --config GROUNDPLAN_XML_IN_MEMORY_BYTES 0
  for t in 2 4 8; do gp "mem_scale_t$t" -f GPKG "$W/mem_scale_t$t.gpkg" "$W/city.gml" --threads $t; done
  python3 - "$W/mem_file_1.json" <<'PY'
import json, sys
print("xml_streamed of the in-memory run:", json.load(open(sys.argv[1]))["reading"].get("xml_streamed"))
PY
fi
if want ab && [ -x "$G/bin/${AB_BIN:-none}" ]; then
  echo "== this build (new) against $AB_BIN (old), ${ROUNDS:-3} alternated rounds; the same outputs"
  for i in $(seq ${ROUNDS:-3}); do
    GP_BIN=$AB_BIN gp "old_file_$i" -f GPKG "$W/old_file_$i.gpkg" "$W/city.gml"
    gp "new_file_$i" -f GPKG "$W/new_file_$i.gpkg" "$W/city.gml"
    GP_BIN=$AB_BIN gp "old_tiles_$i" -f GPKG "$W/old_tiles_$i.gpkg" "$W/tiles" --tiles off
    gp "new_tiles_$i" -f GPKG "$W/new_tiles_$i.gpkg" "$W/tiles" --tiles off
  done
  GP_BIN=$AB_BIN gp old_t1 -f GPKG "$W/old_t1.gpkg" "$W/city.gml" --threads 1
  gp new_t1 -f GPKG "$W/new_t1.gpkg" "$W/city.gml" --threads 1
  for t in 2 4 8; do gp "new_scale_t$t" -f GPKG "$W/new_scale_t$t.gpkg" "$W/city.gml" --threads $t; done
  GP_BIN=$AB_BIN gp old_csv -f CSV -lco GEOMETRY=AS_WKT "$W/old_csv.csv" "$W/city.gml"
  gp new_csv -f CSV -lco GEOMETRY=AS_WKT "$W/new_csv.csv" "$W/city.gml"
  gp new_csv_tiles -f CSV -lco GEOMETRY=AS_WKT "$W/new_csv_tiles.csv" "$W/tiles" --tiles off
  md5sum "$W"/old_csv.csv "$W"/new_csv.csv "$W"/new_csv_tiles.csv | sed "s#$W/##"
fi
if want stream; then
  # Issue 14: the GeoPackage written while the union goes on (streamed_gpkg.h) against after it
  # (--config GROUNDPLAN_WRITE_DURING_UNION NO), the same build; then the two files' tables compared.
  echo "== written during the union (on) against after it (off), ${ROUNDS:-3} alternated rounds"
  NO="--config GROUNDPLAN_WRITE_DURING_UNION NO"
  for i in $(seq ${ROUNDS:-3}); do
    gp "off_file_$i" -f GPKG "$W/off_file_$i.gpkg" "$W/city.gml" $NO
    gp "on_file_$i" -f GPKG "$W/on_file_$i.gpkg" "$W/city.gml"
    grep -o '"after_union_s[^,]*\|"slices_started_during_union[^,]*\|"slices"[^,]*' "$W/on_file_$i.json" | tr '\n' ' '; echo
    gp "off_tiles_$i" -f GPKG "$W/off_tiles_$i.gpkg" "$W/tiles" --tiles off $NO
    gp "on_tiles_$i" -f GPKG "$W/on_tiles_$i.gpkg" "$W/tiles" --tiles off
  done
  python3 - "$W/off_file_1.gpkg" "$W/on_file_1.gpkg" "$W/on_tiles_1.gpkg" <<'PY'
import hashlib, sqlite3, sys
def digest(f):
    c = sqlite3.connect(f); h = hashlib.md5()
    for q in ("SELECT * FROM ground_plans ORDER BY fid", "SELECT * FROM rtree_ground_plans_geom ORDER BY id",
              "SELECT table_name, min_x, min_y, max_x, max_y, srs_id FROM gpkg_contents",
              "SELECT * FROM gpkg_ogr_contents", "SELECT type, name, sql FROM sqlite_master ORDER BY name"):
        for row in c.execute(q): h.update(repr(row).encode())
    return h.hexdigest(), c.execute("PRAGMA integrity_check").fetchone()[0]
for f in sys.argv[1:]: print(f.split("/")[-1], *digest(f))
PY
fi
if want bench && [ -x $G/bin/citygml_read_bench ]; then
  echo "== one core: citygml_read_bench (CPU-time medians), two real samples and a 60 MB city of the generator"
  python3 tests/bench/gen_big_citygml.py "$W/c60.gml" 60 | tail -1
  $G/bin/citygml_read_bench --runs 5 sample_data/niedersachsen-lorup/LoD1_24065862_2_2021-01-25.gml \
    sample_data/plateau-niiza/53395404_bldg_6697_op.gml "$W/c60.gml"
fi

if want e2e; then
echo "== end to end to GeoPackage (3 runs each with all cores)"
for i in 1 2 3; do gp "file_all_$i" -f GPKG "$W/file_all_$i.gpkg" "$W/city.gml"; done
for i in 1 2 3; do gp "tiles_all_$i" -f GPKG "$W/tiles_all_$i.gpkg" "$W/tiles"; done
for i in 1 2 3; do gp "tiles_off_$i" -f GPKG "$W/tiles_off_$i.gpkg" "$W/tiles" --tiles off; done
gp file_t1 -f GPKG "$W/file_t1.gpkg" "$W/city.gml" --threads 1
gp tiles_t1 -f GPKG "$W/tiles_t1.gpkg" "$W/tiles" --threads 1
fi

if want index; then
echo "== GeoPackage spatial index: packed by us (above) against GDAL's own (-lco SPATIAL_INDEX=YES), and none"
for i in 1 2 3; do gp "file_gdalidx_$i" -f GPKG "$W/file_gdalidx_$i.gpkg" "$W/city.gml" -lco SPATIAL_INDEX=YES; done
gp file_noidx -f GPKG "$W/file_noidx.gpkg" "$W/city.gml" -lco SPATIAL_INDEX=NO
python3 - "$W/file_all_1.gpkg" "$W/file_gdalidx_1.gpkg" <<'PY'
import sqlite3, sys
a, b = (sqlite3.connect(f) for f in sys.argv[1:3])
q = "SELECT id, minx, maxx, miny, maxy FROM rtree_ground_plans_geom ORDER BY id"
schema = "SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY type, name"
print("index entries equal:", list(a.execute(q)) == list(b.execute(q)), "| schema equal:",
      list(a.execute(schema)) == list(b.execute(schema)), "| rtreecheck:",
      a.execute("SELECT rtreecheck('rtree_ground_plans_geom')").fetchone()[0])
PY
fi
if want alloc; then
echo "== glibc malloc kept from returning memory to the kernel (GLIBC_TUNABLES), one file, all cores"
for i in 1 2 3; do GLIBC_TUNABLES=glibc.malloc.mmap_threshold=67108864:glibc.malloc.trim_threshold=1073741824 \
  gp "file_tunables_$i" -f GPKG "$W/file_tunables_$i.gpkg" "$W/city.gml"; done
if [ -e $G/lib/libtbbmalloc_proxy.so.2 ]; then
  echo "== TBB's allocator (LD_PRELOAD libtbbmalloc_proxy) against glibc's, one file, all cores"
  for i in 1 2 3; do LD_PRELOAD=$G/lib/libtbbmalloc_proxy.so.2 gp "file_tbbmalloc_$i" -f GPKG "$W/file_tbbmalloc_$i.gpkg" "$W/city.gml"; done
fi
fi

echo "== the writer against ogr2ogr copying the same features (GPKG -> GPKG)"
if want copy && [ -x $G/bin/ogr2ogr ] && [ -e "$W/file_all_1.gpkg" ]; then
  for i in 1 2 3; do
    rm -f "$W/copy.gpkg"; s=$(date +%s%N)
    $G/bin/ogr2ogr -f GPKG "$W/copy.gpkg" "$W/file_all_1.gpkg" ground_plans
    echo "ogr2ogr copy of ground_plans: $(( ($(date +%s%N) - s) / 1000000 )) ms (rc $?)"
  done
fi

echo "== reading scaling (one file, CSV output; 1 and 16 threads: csv_t1, csv_t16 above)"
want scaling && for t in 2 4 8; do gp "scale_t$t" -f CSV -lco GEOMETRY=AS_WKT "$W/scale_t$t.csv" "$W/city.gml" --threads $t; done

if [ "$BIG_MB" != 0 ]; then
  echo "== big city: $BIG_MB MB"
  rm -rf "$W/tiles" "$W"/*.gpkg "$W"/*.csv
  s=$(date +%s); python3 tests/bench/gen_big_citygml.py "$W/big.gml" "$BIG_MB" | tail -1; echo "  made in $(( $(date +%s) - s )) s"
  cat "$W/big.gml" > /dev/null
  gp big_all -f GPKG "$W/big_all.gpkg" "$W/big.gml"
  if want ab && [ -x "$G/bin/${AB_BIN:-none}" ]; then
    GP_BIN=$AB_BIN gp big_old -f GPKG "$W/big_old.gpkg" "$W/big.gml"
    gp big_all_2 -f GPKG "$W/big_all_2.gpkg" "$W/big.gml"
  fi
  if want stream; then
    for i in $(seq ${BIG_ROUNDS:-2}); do
      gp "off_big_$i" -f GPKG "$W/off_big_$i.gpkg" "$W/big.gml" --config GROUNDPLAN_WRITE_DURING_UNION NO
      gp "on_big_$i" -f GPKG "$W/on_big_$i.gpkg" "$W/big.gml"
    done
  fi
  if want xml; then
    gp big_all_2 -f GPKG "$W/big_all_2.gpkg" "$W/big.gml"
    gp big_expat -f GPKG "$W/big_expat.gpkg" "$W/big.gml" --config GROUNDPLAN_XML_IN_MEMORY_BYTES 0
  fi
fi
echo "== done"

#!/bin/bash
# Issue 14, the CityGML reader's speed per core, on the 16-core host (no GDAL there). The bundle:
#   PACK_EXTRA_BINS="build/bin/citygml_read_bench" tests/gpu/pack_cli.sh build B.tar.xz
# and, to compare with an older build in the same call (alternated runs), OLD_BUNDLE=A.tar.xz packed the
# same way from that build. Prints, for each bundle: citygml_read_bench (CPU-time medians, one core: expat
# alone, expat with empty handlers, our reader, reader + footprint) on a generated LoD1 city and the real
# samples, then the CLI's read stage (--stats) with --threads 1 and all cores on the city as one file and
# as 16 tiles. Usage, from the repository root:
#   [OLD_BUNDLE=A.tar.xz] tests/bench/reader_speed_on_device.sh B.tar.xz [CITY_MB] [ROUNDS]
set -u
BUNDLE=${1:?BUNDLE}; MB=${2:-300}; ROUNDS=${3:-3}
OUT=${OUT:-reader-speed-out}; mkdir -p "$OUT"
exec > >(tee "$OUT/reader_speed.log") 2>&1
W=/tmp/gp-reader; rm -rf "$W"; mkdir -p "$W"
unpack() {  # BUNDLE DIR
  mkdir -p "$2" && xz -dc "$1" | tar -C "$2" -xf - || { echo "cannot unpack $1"; exit 1; }
  [ -x "$2/gp/bin/citygml_read_bench" ] || { echo "$1 has no citygml_read_bench (PACK_EXTRA_BINS)"; exit 1; }
}
unpack "$BUNDLE" "$W/new"; NAMES="new"
[ -n "${OLD_BUNDLE:-}" ] && { unpack "$OLD_BUNDLE" "$W/old"; NAMES="old new"; }
with() {  # NAME CMD ARGS...: runs CMD from that bundle, with its libraries (through env: /usr/bin/time can run it)
  local G=$W/$1/gp cmd=$2; shift 2
  env LD_LIBRARY_PATH=$G/lib GDAL_DATA=$G/share/gdal PROJ_DATA=$G/share/proj PROJ_LIB=$G/share/proj "$G/bin/$cmd" "$@"
}
echo "== machine"; date -u; nproc; lscpu | grep -E "Model name|^Thread|^Core|MHz" ; uptime
for n in $NAMES; do echo "$n: $(with $n groundplan --version | head -1)"; done

echo "== inputs"
python3 tests/bench/gen_big_citygml.py "$W/city.gml" "$MB" | tail -1
python3 tests/bench/split_citygml_tiles.py "$W/city.gml" 16 "$W/tiles" | tail -1
cat "$W/city.gml" "$W"/tiles/* > /dev/null
S=sample_data; D=../shared/data
REAL=()
for f in $S/niedersachsen-lorup/LoD1_24065862_2_2021-01-25.gml $S/plateau-niiza/53395404_bldg_6697_op.gml \
         $D/citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml \
         $D/citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml \
         $D/citygml-citygml4j-samples/lod3_building_v2.gml; do [ -f "$f" ] && REAL+=("$f"); done

echo "== one core, in memory: citygml_read_bench (MB/s of CPU time, medians of 7), bundles alternated"
for r in $(seq "$ROUNDS"); do
  for n in $NAMES; do echo "-- $n, round $r"; with $n citygml_read_bench --runs 7 "$W/city.gml" "${REAL[@]}"; done
done

echo "== the CLI's read stage (--stats), city as one file and as 16 tiles, CSV output"
for r in $(seq "$ROUNDS"); do
  for n in $NAMES; do
    for t in 1 $(nproc); do
      for input in city.gml tiles; do
        rm -f "$W/o.csv"
        G=$W/$n/gp
        /usr/bin/time -f "%e %U %S" -o "$W/t" env LD_LIBRARY_PATH=$G/lib GDAL_DATA=$G/share/gdal PROJ_DATA=$G/share/proj \
          PROJ_LIB=$G/share/proj "$G/bin/groundplan" -q --device cpu --stats "$W/s.json" -f CSV \
          -lco GEOMETRY=AS_WKT "$W/o.csv" "$W/$input" --threads $t
        python3 - "$n" "$t" "$input" "$W/s.json" "$W/t" "$W/city.gml" "$W/o.csv" <<'PY'
import hashlib, json, os, sys
n, t, inp, stats, tm, city, csv = sys.argv[1:8]
d = json.load(open(stats)); ts = d["timings_s"]
wall, user, sys_ = open(tm).read().split()[-3:]
mb = os.path.getsize(city) / 1e6
md5 = hashlib.md5(open(csv, "rb").read()).hexdigest()
print("%-4s threads %3s %-8s read %6.2f s = %6.1f MB/s (%6.1f MB/s a thread) | total %6.2f s | cpu %6.1f s | md5 %s"
      % (n, t, inp, ts["read"], mb / ts["read"], mb / ts["read"] / int(t), float(wall),
         float(user) + float(sys_), md5))
PY
      done
    done
  done
done
echo "== done"

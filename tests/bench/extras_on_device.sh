#!/bin/bash
# The benchmarks that need the 16-core host but not the generated city (tests/bench/city_scale_on_device.sh
# does that one): one OGR GeoPackage of 1M footprints read on 1 and 16 threads (issue 22,
# ogr_threads_bench.sh), CityJSON reading against simdjson alone (issue 16, cityjson_read_bench), and
# CityGML reading against expat alone (issue 14, citygml_read_bench). The bundle comes from
#   PACK_EXTRA_BINS="build/bin/cityjson_read_bench build/bin/citygml_read_bench" tests/gpu/pack_cli.sh build B.tar.xz
# and the GeoPackage from gen_footprints_gpkg.py, xz-compressed (the device has no GDAL Python).
# Usage, from the repository root: tests/bench/extras_on_device.sh BUNDLE.tar.xz FOOTPRINTS_1M.gpkg.xz
set -u
BUNDLE=${1:?BUNDLE}; GPKG_XZ=${2:?FOOTPRINTS.gpkg.xz}
W=/tmp/gp-extras; rm -rf "$W"; mkdir -p "$W"
xz -dc "$BUNDLE" | tar -C "$W" -xf - || { echo "cannot unpack $BUNDLE"; exit 1; }
G=$W/gp
export LD_LIBRARY_PATH=$G/lib GDAL_DATA=$G/share/gdal PROJ_DATA=$G/share/proj PROJ_LIB=$G/share/proj
echo "== machine"; date -u; nproc; lscpu | grep -E "Model name|^Thread|^Core"
echo "== OGR input: 1M footprints, 1 and 16 threads (issue 22)"
xz -dc "$GPKG_XZ" > "$W/footprints_1000000.gpkg"
bash tests/bench/ogr_threads_bench.sh "$G" 1000000 3 16 "$W"
echo "== CityJSON against simdjson alone (issue 16)"
[ -x $G/bin/cityjson_read_bench ] && $G/bin/cityjson_read_bench --generate 50000 "$W/cj" 5
echo "== CityGML against expat alone, one core (issue 14)"
[ -x $G/bin/citygml_read_bench ] && $G/bin/citygml_read_bench sample_data/niedersachsen-lorup/LoD1_24065862_2_2021-01-25.gml \
  sample_data/plateau-niiza/53395404_bldg_6697_op.gml
echo "== done"

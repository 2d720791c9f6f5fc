#!/bin/bash
# A folder of PLATEAU tiles (EPSG:6697 latitude/longitude, the CRS that needs an operation to UTM) on the
# 16-core host: COPIES copies of sample_data/plateau-niiza/53395404_bldg_6697_op.gml (3.3 MB each), each moved
# to its own place (latitude 20-79, longitude 138-141 degrees: UTM zone 54 throughout) so that no two copies
# overlap and the union stays the size of a real folder's, read
# by the packed CLI and, when packed beside it as groundplan_before (PACK_EXTRA_BINS), by an older build,
# alternated, with 16 threads and with one. Prints wall, CPU and the outputs' md5 (the two builds must
# agree). Usage, from the repository root, the bundle packed with the tile as input:
#   PACK_EXTRA_BINS=out/groundplan_before tests/gpu/pack_cli.sh build BUNDLE sample_data/plateau-niiza/53395404_bldg_6697_op.gml
#   tests/bench/plateau_folder_on_device.sh BUNDLE [COPIES=200] [ROUNDS=3]
set -u
BUNDLE=${1:?BUNDLE}; COPIES=${2:-200}; ROUNDS=${3:-3}
W=/tmp/gp-plateau; rm -rf "$W"; mkdir -p "$W/tiles"
xz -dc "$BUNDLE" | tar -C "$W" -xf - || { echo "cannot unpack $BUNDLE"; exit 1; }
G=$W/gp
export LD_LIBRARY_PATH=$G/lib GDAL_DATA=$G/share/gdal PROJ_DATA=$G/share/proj PROJ_LIB=$G/share/proj
tile=$G/data/53395404_bldg_6697_op.gml
[ -f "$tile" ] || { echo "the bundle holds no data/53395404_bldg_6697_op.gml"; exit 1; }
python3 - "$tile" "$W/tiles" "$COPIES" <<'PY'
import re, sys
src, out, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
text = open(src, encoding="utf-8").read()
for i in range(n):  # "35.7559 139.5542 55.03": latitude first
    t = re.sub(r"(?<=[\s>])35\.(?=\d)", "%d." % (20 + i % 60), text)
    t = re.sub(r"(?<=[\s>])139\.(?=\d)", "%d." % (138 + (i // 60) % 4), t)
    open("%s/t%03d.gml" % (out, i), "w", encoding="utf-8").write(t)
PY
cat "$W"/tiles/* > /dev/null
echo "== $(date -u) $(nproc) cores; $COPIES tiles, $(du -sh "$W/tiles" | cut -f1)"
bins=(groundplan); [ -x "$G/bin/groundplan_before" ] && bins=(groundplan_before groundplan)
for threads in 16 1; do
  for r in $(seq 1 "$ROUNDS"); do
    for b in "${bins[@]}"; do
      rm -f "$W/$b.csv"
      /usr/bin/time -f "%e %U %S" -o "$W/t" "$G/bin/$b" -q --device cpu --threads $threads -f CSV -lco GEOMETRY=AS_WKT \
        "$W/$b.csv" "$W/tiles" || echo "$b: exit $?"
      read -r wall user sys < "$W/t"
      printf "%-18s threads %2d round %d: wall %6.2f s  cpu %6.2f s  md5 %s\n" "$b" "$threads" "$r" "$wall" \
        "$(awk "BEGIN{print $user + $sys}")" "$(md5sum < "$W/$b.csv" | cut -c1-12)"
    done
    [ "$ROUNDS" -gt 1 ] && [ "$threads" = 1 ] && break  # one round of the slow single-thread runs
  done
done

#!/bin/bash
# SPDX-License-Identifier: MIT
# Issue 15 on the 16-core host (no GDAL, no MPI there): `mpirun -np N groundplan -f GPKG` for N = 1, 2, 4, 8, 16 on a
# generated tiled city (gen_tiled_city.py; default 8 x 8 tiles of 8 x 8 copies of the Lorup tile, about 3.3 GB),
# one thread a rank. Over ranks every rank writes its own plans into a GeoPackage slice and rank 0 appends the
# slices (driver/output/gpkg_rank_slices.h; --stats "writer" says so). Prints a line a run: wall, rank 0's map, the
# reduce step (the slowest rank's reduce + gather) and its share, the write (rank 0's: its slice, the append, the
# index), speed-up and efficiency against N = 1, peak RSS of the largest rank; then the writer entry and per rank:
# tiles, bytes, map, reduce, gather, peak RSS; and whether every N gave the plans of N = 1 (sorted vertex cycles
# and member ids, read back from the GeoPackages). GATHERED (default "16"): the N also run with rank 0 writing every
# plan (-dim XY keeps one writer and changes nothing in these 2D plans), for the write before/after.
# The bundle: the CLI packed with Open MPI (mpirun = orterun, orted, plugins), from the repository root:
#   PACK_MPI=1 tests/gpu/pack_cli.sh build /tmp/gp-mpi.tar.xz
#   tests/bench/mpi_on_device.sh /tmp/gp-mpi.tar.xz [TX TY K] [RANKS...]
# Open MPI is relocated with OPAL_PREFIX (its Debian layout is kept under gp/ompi; checked on the 2-core VM with
# Debian's own Open MPI folders hidden by tmpfs mounts in `unshare -m`: 3 ranks ran from the bundle alone); if
# mpirun cannot start there, the script says so and stops.
# Locally (this VM's GDAL and Open MPI), BUNDLE may be a build folder: tests/bench/mpi_on_device.sh build 2 2 1 1 2
set -u
BUNDLE=${1:?BUNDLE}; TX=${2:-8}; TY=${3:-8}; K=${4:-8}; shift $(( $# < 4 ? $# : 4 ))
RANKS=${*:-1 2 4 8 16}
GATHERED=${GATHERED-16}
OUT=${OUT:-mpi-out}; mkdir -p "$OUT"
exec > >(tee "$OUT/mpi.log") 2>&1
W=/tmp/gp-mpi; rm -rf "$W"; mkdir -p "$W"
MPIRUN=(mpirun --allow-run-as-root --oversubscribe --bind-to none)
if [ -d "$BUNDLE" ]; then  # a local build folder
  G=$(cd "$BUNDLE" && pwd)
  export GDAL_DRIVER_PATH=$G/gdalplugins
else
  xz -dc "$BUNDLE" | tar -C "$W" -xf - || { echo "cannot unpack $BUNDLE"; exit 1; }
  G=$W/gp; O=$G/ompi
  export OPAL_PREFIX=$O PATH=$O/bin:$PATH
  export LD_LIBRARY_PATH=$O/lib/x86_64-linux-gnu/openmpi/lib:$G/lib GDAL_DATA=$G/share/gdal PROJ_DATA=$G/share/proj
  export PMIX_INSTALL_PREFIX=$O PMIX_MCA_mca_base_component_path=$O/lib/x86_64-linux-gnu/pmix2/lib/pmix
  export OMPI_MCA_btl=self,vader OMPI_MCA_plm=isolated 2>/dev/null  # one host: shared memory only
  MPIRUN+=(-x LD_LIBRARY_PATH -x GDAL_DATA -x PROJ_DATA)
fi
echo "== machine"; date -u; nproc; lscpu | grep -E "Model name|^Core|^Socket"; free -g | head -2
$G/bin/groundplan --version || { ldd $G/bin/groundplan | grep "not found"; exit 1; }
if ! "${MPIRUN[@]}" -np 2 $G/bin/groundplan --version; then
  unset OMPI_MCA_plm
  "${MPIRUN[@]}" -np 2 $G/bin/groundplan --version ||
    { echo "mpirun does not start from the bundle (OPAL_PREFIX=$O): not workable here"; exit 1; }
fi

echo "== city: gen_tiled_city.py $TX x $TY tiles, $K x $K copies each"
s=$(date +%s); python3 tests/bench/gen_tiled_city.py "$W/city" "$TX" "$TY" "$K" | tail -1
echo "  $(ls "$W/city" | wc -l) files, $(du -sb "$W/city" | cut -f1) bytes, made in $(( $(date +%s) - s )) s"
cat "$W"/city/* > /dev/null  # in the page cache for every run

run() {  # run NAME N [extra options]: one mpirun, its wall time and stats
  local name=$1 n=$2; shift 2
  rm -rf "$W/out_$name.gpkg"
  local s; s=$(date +%s.%N)
  # GeoPackage, the fast writer (GDAL's CSV writer alone takes ~10 s for these 262k plans on one rank)
  /usr/bin/time -f %M -o "$W/rss_$name" "${MPIRUN[@]}" -np "$n" $G/bin/groundplan -q --device cpu --threads 1 --tiles on \
    --stats "$W/s_$name.json" "$@" -f GPKG "$W/out_$name.gpkg" "$W/city" || { echo "$name: failed"; return; }
  python3 -c "import sys; print(float(sys.argv[2]) - float(sys.argv[1]))" "$s" "$(date +%s.%N)" > "$W/wall_$name"
}
for n in $RANKS; do
  run "$n" "$n"
  case " $GATHERED " in *" $n "*) [ "$n" -gt 1 ] && run "${n}g" "$n" -dim XY ;; esac
done
NAMES=""; for n in $RANKS; do NAMES+=" $n"; case " $GATHERED " in *" $n "*) [ "$n" -gt 1 ] && NAMES+=" ${n}g" ;; esac; done

python3 - "$W" $NAMES <<'PY'
import json, sqlite3, struct, sys
w, ranks = sys.argv[1], sys.argv[2:]
def rings(blob):  # GeoPackage geometry: 'GP' header, envelope, then WKB (Polygon or MultiPolygon)
    env = (0, 32, 48, 48, 64)[(blob[3] >> 1) & 7]
    b, out = memoryview(blob)[8 + env:], []
    def poly(o, e):
        (nr,) = struct.unpack_from(e + "I", b, o); o += 4
        for _ in range(nr):
            (np_,) = struct.unpack_from(e + "I", b, o); o += 4
            pts = [struct.unpack_from(e + "dd", b, o + 16 * i) for i in range(np_)][:-1]; o += 16 * np_
            k = min(range(len(pts)), key=lambda i: pts[i])
            out.append(tuple(pts[k:] + pts[:k]))
        return o
    e = "<" if b[0] == 1 else ">"
    (t,) = struct.unpack_from(e + "I", b, 1)
    if t == 3: poly(5, e)
    else:
        (ng,) = struct.unpack_from(e + "I", b, 5); o = 9
        for _ in range(ng): o = poly(o + 5, "<" if b[o] == 1 else ">")
    return tuple(out)
def plans(n):
    db = sqlite3.connect(f"{w}/out_{n}.gpkg")
    g = db.execute("SELECT column_name FROM gpkg_geometry_columns WHERE table_name='ground_plans'").fetchone()[0]
    return sorted((rings(geom), ids) for geom, ids in db.execute(f'SELECT "{g}", building_ids FROM ground_plans'))
base_wall = base = None
for n in ranks:
    try:
        s = json.load(open(f"{w}/s_{n}.json")); wall = float(open(f"{w}/wall_{n}").read())
    except OSError:
        print(f"np {n}: no result"); continue
    per = s.get("mpi", {}).get("per_rank") or [{"tiles": s["tiles"]["tiles"], "bytes": s["reading"]["bytes"],
        "map_s": s["tiles"]["map_s"], "reduce_s": s["tiles"]["reduce_s"], "gather_s": 0,
        "peak_rss_bytes": int(open(f"{w}/rss_{n}").read().split()[-1]) * 1024}]  # np 1: no "mpi" section
    k = int(n.rstrip("g"))
    reduce = max(r["reduce_s"] + r["gather_s"] for r in per)
    write = s["timings_s"]["write"]
    base_wall = base_wall or wall
    p = plans(n); base = base or p
    label = f"{k:>2}" + (" gathered" if n.endswith("g") else "")
    print(f"np {label}: wall {wall:7.2f} s, rank 0 map {per[0]['map_s']:6.2f} s, reduce+gather {reduce:6.2f} s "
          f"({100 * reduce / wall:4.1f} %), write {write:6.2f} s ({100 * write / wall:4.1f} %), speed-up "
          f"{base_wall / wall:5.2f}, efficiency {100 * base_wall / wall / k:5.1f} %, peak RSS max "
          f"{max(r['peak_rss_bytes'] for r in per) / 2**20:6.0f} MiB, plans {len(p)}, same as np {ranks[0]}: {p == base}")
    print("    writer:", json.dumps(s.get("writer")))
    for i, r in enumerate(per):
        print(f"    rank {i:>2}: tiles {r['tiles']:>3} bytes {r['bytes'] / 2**20:8.1f} MiB map {r['map_s']:7.2f} s "
              f"reduce {r['reduce_s']:6.2f} s gather {r['gather_s']:6.2f} s peak RSS {r['peak_rss_bytes'] / 2**20:6.0f} MiB")
    print("    tiles:", json.dumps(s["tiles"]))
PY

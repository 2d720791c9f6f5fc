#!/bin/bash
# SPDX-License-Identifier: MIT
# One process on a folder of tiles against one process per tile, and MPI ranks, on a many-core host (issue 40).
# The 1.5 GB LoD1 city of gen_big_citygml.py cut into 16 tiles (split_citygml_tiles.py), page cache warm,
# GeoPackage output, --device cpu. Prints one line a run (wall, --stats stages, CPU, faults, context switches,
# peak RSS) and medians a case. The CLI comes packed by tests/gpu/pack_cli.sh (PACK_MPI=1 for the mpi section;
# PACK_EXTRA_LIBS with libjemalloc.so.2 libmimalloc.so.2 libtbbmalloc_proxy.so.2 for the alloc section; a second
# CLI as AB_BIN, packed with PACK_EXTRA_BINS, for before/after). Usage, from the repository root:
#   [SECTIONS="same file alone indep one knobs alloc mpi perf"] [AB_BIN=groundplan_before] [ROUNDS=3] \
#     tests/bench/scale_on_device.sh BUNDLE.tar.xz [CITY_MB] [TILES]
# PERF=path/to/perf (a perf binary, its libraries beside it in PERF_LIB) for the perf section (cpu-clock samples).
set -u
BUNDLE=${1:?BUNDLE}; MB=${2:-1500}; NT=${3:-16}
SECTIONS=${SECTIONS:-"alone indep one knobs mpi"}
ROUNDS=${ROUNDS:-3}
want() { [[ " $SECTIONS " == *" $1 "* ]]; }
OUT=${OUT:-scale-out}; mkdir -p "$OUT"
exec > >(tee "$OUT/scale.log") 2>&1
W=/tmp/gp-scale
source "$(dirname "$0")/../gpu/unpack_bundle.sh"
HERE=$(cd "$(dirname "$0")" && pwd)
if [ -n "${NEW_BIN:-}" ]; then  # a newer CLI (xz) in place of the bundle's, which stays as groundplan_before (AB_BIN)
  mv $G/bin/groundplan $G/bin/groundplan_before && xz -dc "$NEW_BIN" > $G/bin/groundplan && chmod +x $G/bin/groundplan
fi
echo "== machine"; date -u; nproc; lscpu | grep -E "Model name|^Thread|^Core|^Socket|^NUMA node\(s\)"; free -g | head -2
$G/bin/groundplan --version || { ldd $G/bin/groundplan | grep "not found"; exit 1; }
TIME="%e %U %S %M %R %c %w"  # wall, user, sys, peak RSS KiB, minor faults, involuntary, voluntary switches

line() {  # NAME STATS.json TIME.txt -> one line
  python3 - "$@" <<'PY'
import json, sys
name, stats, tm = sys.argv[1:4]
wall, user, sys_, rss, minflt, invol, vol = open(tm).read().split()[-7:]
try:
    d = json.load(open(stats))
except Exception:
    print("%-26s wall %6.2f s (no stats)" % (name, float(wall))); sys.exit()
t = d["timings_s"]
tl = d.get("tiles") or {}
extra = " map %.2f reduce %.2f" % (tl.get("map_s", 0), tl.get("reduce_s", 0)) if tl else ""
print("%-26s wall %6.2f total %5.2f | read %5.2f fp %5.2f union %5.2f write %5.2f (idx %4.2f)%s | cpu %6.1f (sys %4.1f) "
      "| minflt %7.0fk | ctx inv %6s vol %7s | rss %5.0f MiB" % (name, float(wall), t.get("total", 0), t["read"],
      t["footprints"], t["union"], t["write"], t.get("spatial_index", 0), extra, float(user) + float(sys_),
      float(sys_), int(minflt) / 1000, invol, vol, int(rss) / 1024))
PY
}
gp() {  # NAME ARGS... : one run, its line
  local name=$1; shift
  rm -rf "$W/out/$name.gpkg" "$W/out/$name.csv"
  /usr/bin/time -f "$TIME" -o "$W/$name.time" $G/bin/${GP_BIN:-groundplan} -q --device cpu --stats "$W/$name.json" "$@"
  local rc=$?
  [ $rc = 0 ] && line "$name" "$W/$name.json" "$W/$name.time" || echo "$name: exit $rc"
  rm -rf "$W/out/$name.gpkg" "$W/out/$name.csv"
}
median() {  # PREFIX: the median wall of runs $W/PREFIX_*.time
  python3 - "$W" "$1" <<'PY'
import glob, statistics, sys
w, p = sys.argv[1:3]
v = sorted(float(open(f).read().split()[-7]) for f in glob.glob(f"{w}/{p}_*.time")
           if f[len(f"{w}/{p}_"):-len(".time")].isdigit())
print("  median %-24s %.2f s of %s" % (p, statistics.median(v), " / ".join("%.2f" % x for x in v)) if v else "  %s: none" % p)
PY
}

echo "== city: gen_big_citygml.py $MB MB, $NT tiles"
s=$(date +%s); mkdir -p "$W/out"
python3 "$HERE/gen_big_citygml.py" "$W/city.gml" "$MB" | tail -1
python3 "$HERE/split_citygml_tiles.py" "$W/city.gml" "$NT" "$W/tiles" | tail -1; echo "  made in $(( $(date +%s) - s )) s"
cat "$W/city.gml" > /dev/null; cat "$W"/tiles/* > /dev/null

indep() {  # NAME [ARGS...]: one 1-thread process per tile, all at once; the round's wall and the processes' medians
  local name=$1; shift
  local s; s=$(date +%s.%N)
  local i=0 pids=()
  for f in "$W"/tiles/*.gml; do
    /usr/bin/time -f "$TIME" -o "$W/${name}_p$i.time" $G/bin/${GP_BIN:-groundplan} -q --device cpu --threads 1 \
      --stats "$W/${name}_p$i.json" "$@" -f GPKG "$W/out/${name}_p$i.gpkg" "$f" &
    pids+=($!); i=$((i + 1))
  done
  wait "${pids[@]}"  # not a bare wait: that waits for the tee of the log too
  python3 - "$W" "$name" "$s" "$(date +%s.%N)" <<'PY'
import glob, json, statistics, sys
w, name, s, e = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
walls, cpus, tot, st = [], [], [], {}
for f in sorted(glob.glob(f"{w}/{name}_p*.time")):
    wall, user, sys_ = open(f).read().split()[-7:-4]
    walls.append(float(wall)); cpus.append(float(user) + float(sys_))
    d = json.load(open(f.replace(".time", ".json")))
    tot.append(d["timings_s"]["total"])
    for k in ("read", "footprints", "union", "write", "spatial_index"):
        st.setdefault(k, []).append(d["timings_s"].get(k, 0))
med = lambda v: statistics.median(v)
print("%-26s wall %6.2f (slowest process %.2f, median %.2f; in-process total median %.2f, max %.2f) | read %.2f fp %.2f "
      "union %.2f write %.2f idx %.2f (medians) | cpu sum %.1f s" % (name, e - s, max(walls), med(walls), med(tot),
      max(tot), med(st["read"]), med(st["footprints"]), med(st["union"]), med(st["write"]), med(st["spatial_index"]),
      sum(cpus)))
open(f"{w}/{name}.time", "w").write("%.3f 0 0 0 0 0 0\n" % (e - s))
PY
  rm -f "$W"/out/${name}_p*.gpkg
}

if want same && [ -n "${AB_BIN:-}" ]; then
  echo "== the same plans from this build and $AB_BIN (CSV WKT, md5), one process and the tiled run"
  for m in off on; do
    for b in groundplan $AB_BIN; do
      $G/bin/$b -q --device cpu --tiles $m -f CSV -lco GEOMETRY=AS_WKT "$W/out/same_${b}_$m.csv" "$W/tiles"
      echo "$b --tiles $m: $(md5sum < "$W/out/same_${b}_$m.csv" | cut -c1-12) $(wc -l < "$W/out/same_${b}_$m.csv") lines"
    done
  done
  rm -f "$W"/out/same_*.csv
fi
if want file; then
  echo "== the city as one 1.5 GB file, all cores"
  for i in $(seq $ROUNDS); do
    gp "file_$i" -f GPKG "$W/out/file_$i.gpkg" "$W/city.gml"
    [ -n "${AB_BIN:-}" ] && GP_BIN=$AB_BIN gp "bfile_$i" -f GPKG "$W/out/bfile_$i.gpkg" "$W/city.gml"
  done
  median file; median bfile
fi
if want alone; then
  echo "== one tile alone, one thread"
  for i in $(seq $ROUNDS); do gp "alone_$i" --threads 1 -f GPKG "$W/out/alone_$i.gpkg" "$W/tiles/tile_00.gml"; done
  echo "== startup alone: groundplan --version"
  for i in 1 2 3; do /usr/bin/time -f "%e s" $G/bin/groundplan --version > /dev/null; done
fi
if want indep; then
  echo "== $NT independent 1-thread processes, one per tile (each its own GeoPackage)"
  for i in $(seq $ROUNDS); do
    indep "indep_$i"
    [ -n "${AB_BIN:-}" ] && GP_BIN=$AB_BIN indep "bindep_$i"
  done
  median indep; median bindep
fi
if want one; then
  echo "== one process on the folder (one GeoPackage)"
  for i in $(seq $ROUNDS); do
    gp "off16_$i" -f GPKG "$W/out/off16_$i.gpkg" "$W/tiles" --tiles off --threads 16
    gp "off32_$i" -f GPKG "$W/out/off32_$i.gpkg" "$W/tiles" --tiles off --threads 32
    gp "on16_$i" -f GPKG "$W/out/on16_$i.gpkg" "$W/tiles" --tiles on --threads 16
    gp "on32_$i" -f GPKG "$W/out/on32_$i.gpkg" "$W/tiles" --tiles on --threads 32
    [ -n "${AB_BIN:-}" ] && GP_BIN=$AB_BIN gp "boff16_$i" -f GPKG "$W/out/boff16_$i.gpkg" "$W/tiles" --tiles off --threads 16
    [ -n "${AB_BIN:-}" ] && GP_BIN=$AB_BIN gp "boff32_$i" -f GPKG "$W/out/boff32_$i.gpkg" "$W/tiles" --tiles off --threads 32
    [ -n "${AB_BIN:-}" ] && GP_BIN=$AB_BIN gp "bon16_$i" -f GPKG "$W/out/bon16_$i.gpkg" "$W/tiles" --tiles on --threads 16
  done
  for p in off16 off32 on16 on32 boff16 boff32 bon16; do median $p; done
fi
if want knobs; then
  echo "== one process, 16 threads: what each knob changes"
  for i in $(seq $ROUNDS); do
    gp "chunk32m_$i" -f GPKG "$W/out/chunk32m_$i.gpkg" "$W/tiles" --tiles off --threads 16 --read-chunk-bytes 33554432
    gp "writeafter_$i" -f GPKG "$W/out/writeafter_$i.gpkg" "$W/tiles" --tiles off --threads 16 --config GROUNDPLAN_WRITE_DURING_UNION NO
    gp "csv_$i" -f CSV -lco GEOMETRY=AS_WKT "$W/out/csv_$i.csv" "$W/tiles" --tiles off --threads 16
  done
  for p in chunk32m writeafter csv; do median $p; done
fi
if want alloc; then
  echo "== allocators preloaded, one process 16 threads, and the 16 processes"
  for a in ${ALLOCS:-libjemalloc.so.2 libmimalloc.so.2 libtbbmalloc_proxy.so.2}; do
    [ -e "$G/lib/$a" ] || continue
    n=${a%%.so*}; n=${n#lib}
    for i in $(seq $ROUNDS); do LD_PRELOAD=$G/lib/$a GP_BIN=${ALLOC_BIN:-groundplan} gp "${n}_$i" -f GPKG "$W/out/${n}_$i.gpkg" "$W/tiles" --tiles off --threads 16; done
    median "$n"
  done
fi
if want perf && [ -n "${PERF:-}" ]; then
  echo "== perf (cpu-clock samples): one process 16 threads, then the 16 processes"
  export LD_LIBRARY_PATH=$LD_LIBRARY_PATH:${PERF_LIB:-}
  $PERF record -F 1999 -e cpu-clock -o "$W/one.perf" -- $G/bin/groundplan -q --device cpu --threads 16 --tiles off \
    -f GPKG "$W/out/perf_one.gpkg" "$W/tiles" 2>&1 | tail -2
  $PERF report -i "$W/one.perf" --sort dso,sym --percent-limit 0.3 --stdio 2>/dev/null | grep "%" | head -80 > "$OUT/perf_one.txt"
  head -40 "$OUT/perf_one.txt"
  $PERF record -F 1999 -e cpu-clock -a -o "$W/indep.perf" 2>/dev/null & pp=$!
  sleep 1; indep perf_indep; kill -INT $pp; wait $pp
  $PERF report -i "$W/indep.perf" --comm groundplan --sort dso,sym --percent-limit 0.3 --stdio 2>/dev/null | grep "%" |
    head -80 > "$OUT/perf_indep.txt"
  head -40 "$OUT/perf_indep.txt"
fi
if want mpi && [ -d "$G/ompi" ]; then
  echo "== MPI: mpirun -np N, --tiles on --threads 1 (GeoPackage slices by every rank)"
  O=$G/ompi
  export OPAL_PREFIX=$O PATH=$O/bin:$PATH
  export LD_LIBRARY_PATH=$O/lib/x86_64-linux-gnu/openmpi/lib:$LD_LIBRARY_PATH
  export PMIX_INSTALL_PREFIX=$O PMIX_MCA_mca_base_component_path=$O/lib/x86_64-linux-gnu/pmix2/lib/pmix
  export OMPI_MCA_btl=self,vader OMPI_MCA_plm=isolated PMIX_MCA_pcompress_base_silence_warning=1
  MPIRUN=(mpirun --allow-run-as-root --oversubscribe --bind-to none -x LD_LIBRARY_PATH -x GDAL_DATA -x PROJ_DATA)
  "${MPIRUN[@]}" -np 2 $G/bin/groundplan --version > /dev/null || { unset OMPI_MCA_plm; "${MPIRUN[@]}" -np 2 $G/bin/groundplan --version; }
  for i in 1 2; do /usr/bin/time -f "mpirun -np 16 true: %e s" "${MPIRUN[@]}" -np 16 true; done
  for i in 1 2; do /usr/bin/time -f "mpirun -np 16 groundplan --version: %e s" "${MPIRUN[@]}" -np 16 $G/bin/groundplan --version > /dev/null; done
  mpi() {  # NAME N [ARGS]
    local name=$1 n=$2; shift 2
    /usr/bin/time -f "$TIME" -o "$W/$name.time" "${MPIRUN[@]}" -np "$n" $G/bin/${GP_BIN:-groundplan} -q --device cpu \
      --tiles on --stats "$W/$name.json" "$@" -f GPKG "$W/out/$name.gpkg" "$W/tiles" || { echo "$name: failed"; return; }
    line "$name" "$W/$name.json" "$W/$name.time"
    python3 - "$W/$name.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); m = d.get("mpi")
if m:
    pr = m["per_rank"]
    print("    threads a rank %s | per rank map s: " % d["reading"]["threads"] + " ".join("%.2f" % r["map_s"] for r in pr)
          + " | reduce+gather max %.2f | writer %s" % (max(r["reduce_s"] + r["gather_s"] for r in pr),
                                                     json.dumps(d.get("writer"))))
PY
    rm -f "$W/out/$name.gpkg"
  }
  for n in ${MPI_RANKS:-1 2 4 8 16}; do
    for i in $(seq ${MPI_ROUNDS:-1}); do
      mpi "np${n}_$i" "$n" --threads 1
      [ -n "${AB_BIN:-}" ] && GP_BIN=$AB_BIN mpi "bnp${n}_$i" "$n" --threads 1
      [ -n "${MPI_DEFAULT:-}" ] && mpi "dnp${n}_$i" "$n"  # no --threads: the CLI's default a rank
      [ -n "${MPI_DEFAULT:-}" ] && [ -n "${AB_BIN:-}" ] && GP_BIN=$AB_BIN mpi "bdnp${n}_$i" "$n"
    done
  done
  for n in ${MPI_HYBRID:-}; do  # ranks x threads
    r=${n%x*}; t=${n#*x}; mpi "hy${n}_1" "$r" --threads "$t"
  done
  for n in ${MPI_RANKS:-1 2 4 8 16}; do
    median "np$n"; [ -n "${AB_BIN:-}" ] && median "bnp$n"
    [ -n "${MPI_DEFAULT:-}" ] && median "dnp$n" && [ -n "${AB_BIN:-}" ] && median "bdnp$n"
  done
  for n in ${MPI_HYBRID:-}; do median "hy$n"; done
fi
echo "== done"; date -u

#!/bin/bash
# The union per core against other libraries (issue 39): ours (build_ground_plans, 1 thread), Clipper2 (one Union
# call of every path; one Union per group of footprints whose boxes meet), Boost.Polygon, and GEOS
# DisjointSubsetUnion where the loaded libgeos_c has it (GEOS >= 3.12: GEOS_DSU_LIB=dir, as dsu_on_device.sh builds
# it), on the synthetic city and on footprint files. One process per (engine, input), pinned to one core; prints
# bench_union's lines and, per input, each anchor's median CPU time over ours (> 1: ours is faster).
#
# Clipper2 is built for the benchmark only and never enters the repository: CLIPPER2=<a Clipper2 checkout or bare
# git repository> is exported (tag CLIPPER2_TAG, default Clipper2_2.0.1) into BUILD/_deps, and BUILD is configured
# with GROUNDPLAN_BENCH_CLIPPER2_DIR pointing there. Boost.Polygon comes from Debian's libboost-dev headers.
#
# Usage, from the repository root:
#   CLIPPER2=/path/to/Clipper2 tests/bench/union_anchors.sh BUILD ["60000 200000"] [FOOTPRINTS.csv ...]
#   FOOTPRINTS.csv: `tests/bench/union_anchors.sh --footprints SOURCE OUT.csv` writes one (the CLI's footprints
#   layer as WKT with 17 digits); CPU=1 (the core), RUNS=5, GROUNDPLAN=build/bin/groundplan.
set -u
if [ "${1:-}" = "--footprints" ]; then
  SRC=${2:?SOURCE}; OUTCSV=${3:?OUT.csv}; T=$(mktemp -d)
  "${GROUNDPLAN:-build/bin/groundplan}" --threads 1 -f GPKG "$T/fp.gpkg" "$SRC" footprints >"$T/log" 2>&1 ||
    { tail -3 "$T/log"; rm -rf "$T"; exit 1; }
  ogr2ogr --config OGR_WKT_PRECISION 17 -f CSV "$OUTCSV" "$T/fp.gpkg" footprints -lco GEOMETRY=AS_WKT -select fp_id
  rc=$?; rm -rf "$T"; exit $rc
fi
BUILD=${1:?BUILD}; SIZES=${2:-60000 200000}; shift; [ $# -gt 0 ] && shift
CPU=${CPU:-1}; RUNS=${RUNS:-5}
if [ -n "${CLIPPER2:-}" ]; then
  D="$BUILD/_deps"; rm -rf "$D/CPP"; mkdir -p "$D"
  if [ -d "$CLIPPER2/CPP/Clipper2Lib" ]; then cp -r "$CLIPPER2/CPP" "$D/"
  else git --git-dir="$CLIPPER2" archive "${CLIPPER2_TAG:-Clipper2_2.0.1}" CPP/Clipper2Lib | tar -C "$D" -xf - || exit 1; fi
  cmake -S . -B "$BUILD" -DGROUNDPLAN_BENCH_CLIPPER2_DIR="$(cd "$D" && pwd)/CPP/Clipper2Lib" >/dev/null || exit 1
fi
nice ninja -C "$BUILD" bench_union >/dev/null || exit 1
B="$BUILD/bin/bench_union"
echo "== $(date -u) $(nproc) cores, $(lscpu | grep 'Model name' | sed 's/ *Model name: *//'), load $(cut -d' ' -f1-3 /proc/loadavg), core $CPU"
echo "== engine n runs median_wall_s min_wall_s max_wall_s median_cpu_s plans peak_rss_mib input_rss_mib min_cpu_s"
ratios() {  # input-name, then lines
  python3 - "$@" <<'PY'
import sys
name, lines = sys.argv[1], [l.split() for l in sys.argv[2:] if l.strip()]
by = {l[0]: l for l in lines}
if "ours" not in by: sys.exit()
o_cpu, o_min = float(by["ours"][6]), float(by["ours"][10])
parts = ["%s/ours %.2fx (min %.2fx)" % (e, float(l[6]) / o_cpu, float(l[10]) / o_min) for e, l in by.items() if e != "ours"]
print("ratio %s: %s" % (name, "; ".join(parts)))
PY
}
one() {  # name, then bench_union's input arguments
  local name=$1; shift; local lines=()
  for e in ours clipper2_groups clipper2 boost dsu; do
    local runs=$RUNS
    case $e in clipper2|boost|dsu) runs=3 ;; esac
    local l
    if [ $e = dsu ]; then
      [ -n "${GEOS_DSU_LIB:-}" ] || continue
      l=$(LD_LIBRARY_PATH=$GEOS_DSU_LIB taskset -c "$CPU" "$B" "$@" --engine dsu --threads 1 --runs $runs 2>/dev/null)
    else
      l=$(taskset -c "$CPU" "$B" "$@" --engine $e --threads 1 --runs $runs 2>/dev/null)
    fi
    [ -n "$l" ] && { echo "$l $name"; lines+=("$l"); }
  done
  ratios "$name" "${lines[@]}"
}
for n in $SIZES; do one "city$n" --n "$n"; done
# small files: each timed run repeats the call for at least 0.2 s of CPU time, timed per call
for f in "$@"; do one "$(basename "$f" .csv)" --input "$f" --min-time 0.2; done

#!/bin/bash
# The union's honest baseline (issue 20's and 23's speed goals): GEOS DisjointSubsetUnion, which needs
# GEOS >= 3.12 while Debian bookworm has 3.11. On a host without GEOS packages (the 16-core GPU host):
# builds GEOS from a source tarball (e.g. `git archive` of a release tag), then runs bench_union (packed by
# tests/gpu/pack_cli.sh with PACK_EXTRA_BINS=build/bin/bench_union) against it: the same binary loads the
# new libgeos_c.so.1 through LD_LIBRARY_PATH and finds GEOSDisjointSubsetUnion_r at run time.
# Prints one line per (engine, n) as bench_union does, then the ratios per n. Usage, from the repository root:
#   tests/bench/dsu_on_device.sh BUNDLE.tar.xz GEOS.tar.xz ["6000 60000 200000"] [DSU_MAX_N]
# AB_BIN=NAME (a second bench_union packed beside it, e.g. the build before a change): for each n, ROUNDS
# (default 3) alternated rounds of both on 1 thread and on all cores first, one line each, marked "before".
set -u
BUNDLE=${1:?BUNDLE}; GEOS_TAR=${2:?GEOS.tar.xz}; SIZES=${3:-6000 60000 200000 1000000}; DSU_MAX=${4:-1000000}
OUT=${OUT:-dsu-out}; mkdir -p "$OUT"
exec > >(tee "$OUT/dsu.log") 2>&1
W=/tmp/gp-dsu; rm -rf "$W"; mkdir -p "$W/src" "$W/geos"
xz -dc "$BUNDLE" | tar -C "$W" -xf - || { echo "cannot unpack $BUNDLE"; exit 1; }
xz -dc "$GEOS_TAR" | tar -C "$W/src" -xf - || { echo "cannot unpack $GEOS_TAR"; exit 1; }
G=$W/gp
echo "== machine"; date -u; nproc; lscpu | grep -E "Model name|^Thread|^Core"; free -g | head -2
echo "== GEOS build"
S=$(ls -d "$W"/src/*/ | head -1)
t0=$(date +%s)
cmake -S "$S" -B "$W/geos-build" -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF -DBUILD_BENCHMARKS=OFF \
  -DCMAKE_INSTALL_PREFIX="$W/geos" >"$W/geos-cmake.log" 2>&1 || { tail -20 "$W/geos-cmake.log"; exit 1; }
cmake --build "$W/geos-build" -j"$(nproc)" >"$W/geos-build.log" 2>&1 || { tail -30 "$W/geos-build.log"; exit 1; }
cmake --install "$W/geos-build" >/dev/null 2>&1 || { echo "GEOS install failed"; exit 1; }
echo "built in $(( $(date +%s) - t0 )) s: $(ls "$W"/geos/lib*/libgeos_c.so.1)"
GEOSLIB=$(dirname "$(ls "$W"/geos/lib*/libgeos_c.so.1)")
B() { LD_LIBRARY_PATH=$GEOSLIB:$G/lib timeout 900 "$G/bin/bench_union" "$@" 2>>"$W/stderr.log"; }
echo "== engine n runs median_wall_s min_wall_s max_wall_s median_cpu_s plans peak_rss_mib input_rss_mib min_cpu_s"
A() { LD_LIBRARY_PATH=$GEOSLIB:$G/lib timeout 900 "$G/bin/$AB_BIN" "$@" 2>>"$W/stderr.log"; }
for n in $SIZES; do
  if [ -n "${AB_BIN:-}" ]; then
    for r in $(seq "${ROUNDS:-3}"); do
      echo "$(A --n "$n" --engine ours --threads 1 --runs 3) threads=1 before round=$r"
      echo "$(B --n "$n" --engine ours --threads 1 --runs 3) threads=1 after round=$r"
      echo "$(A --n "$n" --engine ours --threads 0 --runs 3) threads=$(nproc) before round=$r"
      echo "$(B --n "$n" --engine ours --threads 0 --runs 3) threads=$(nproc) after round=$r"
    done
  fi
  o1=$(B --n "$n" --engine ours --threads 1 --runs 5); echo "$o1 threads=1"
  on=$(B --n "$n" --engine ours --threads 0 --runs 5); echo "$on threads=$(nproc)"
  d=""; [ "$n" -le "$DSU_MAX" ] && { d=$(B --n "$n" --engine dsu --runs $([ "$n" -le 60000 ] && echo 3 || echo 1)); echo "$d"; }
  u=""; [ "$n" -le 60000 ] && { u=$(B --n "$n" --engine geos --runs 1); echo "$u (UnaryUnion)"; }
  python3 - "$n" "$o1" "$on" "$d" "$u" <<'PY'
import sys
n, o1, on, d, u = sys.argv[1:]
w = lambda line: float(line.split()[3]) if line.strip() else None
c1, cn, dd, uu = w(o1), w(on), w(d), w(u)
parts = []
if dd: parts.append("DSU/ours(1 thread) %.2fx, DSU/ours(all cores) %.1fx" % (dd / c1, dd / cn))
if uu: parts.append("UnaryUnion/ours(1 thread) %.1fx" % (uu / c1))
if dd and uu: parts.append("UnaryUnion/DSU %.2fx" % (uu / dd))
print("ratio n=%s: %s" % (n, "; ".join(parts) or "-"))
PY
done
sort -u "$W/stderr.log"

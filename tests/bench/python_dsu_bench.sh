#!/bin/bash
# Issue 23's honest baseline at Python level: groundplan.union on one core against GEOS DisjointSubsetUnion,
# conversion in and out of Python included (tests/bench/python_union_bench.py says what each side counts).
# DSU needs GEOS >= 3.12 and Debian bookworm has 3.11: this builds libgeos_c alone (Release, no tests) from a
# GEOS source archive into out/geos-dsu/ once (a second run reuses it; an interrupted build resumes), then runs
# the benchmark with GEOS_DSU_LIB pointing at it. The module must be built (build/python).
# Usage, from the repository root:
#   tests/bench/python_dsu_bench.sh GEOS.tar.xz [benchmark arguments, e.g. --n 60000 --repeat 3]
# JOBS=2 by default (nice); on a shared VM the GEOS build takes long (404 objects).
set -eu
GEOS_TAR=${1:?GEOS source archive, e.g. geos-3.14.1.tar.xz}; shift
W=$PWD/out/geos-dsu; JOBS=${JOBS:-2}
lib=$(ls "$W"/install/lib*/libgeos_c.so.1 2>/dev/null | head -1 || true)
if [ -z "$lib" ]; then
  mkdir -p "$W/src"
  [ -n "$(ls -A "$W/src")" ] || xz -dc "$GEOS_TAR" | tar -C "$W/src" -xf -
  S=$(ls -d "$W"/src/*/ | head -1)
  [ -f "$W/build/build.ninja" ] || cmake -S "$S" -B "$W/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF \
    -DBUILD_BENCHMARKS=OFF -DBUILD_GEOSOP=OFF -DCMAKE_INSTALL_PREFIX="$W/install" >"$W/cmake.log"
  nice ninja -C "$W/build" -j"$JOBS" geos_c
  cmake --install "$W/build" >/dev/null
  lib=$(ls "$W"/install/lib*/libgeos_c.so.1 | head -1)
fi
echo "# $(date -u '+%F %H:%M UTC'); $(nproc) CPUs; load $(cut -d' ' -f1-3 /proc/loadavg); GEOS_DSU_LIB=$lib"
GEOS_DSU_LIB=$lib PYTHONPATH=${PYTHONPATH:+$PYTHONPATH:}$PWD/build/python /usr/bin/python3 tests/bench/python_union_bench.py "$@"

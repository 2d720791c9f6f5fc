#!/bin/bash
# Issue 5 timings on another machine (the GPU hosts: no GDAL, GEOS or PROJ there, so no
# decompose_bench): decompose_replay built with g++ from the decomposition's sources, on meshes
# dumped here with `decompose_bench --dump DUMP`. Same flags as groundplan_core's Release build.
# Usage (repository root): tests/bench/decompose_on_device.sh DUMP   (logs also to $OUT when set)
set -u
DUMP=${1:?usage: decompose_on_device.sh DUMP}
OUT=${OUT:-decompose-out}
mkdir -p "$OUT"
exec > >(tee "$OUT/decompose.log") 2>&1
echo "== machine"; date -u; nproc; lscpu | grep -E "^(Model name|CPU max MHz|CPU MHz|Thread|Core|Socket|L2|L3)" ; uptime
g++ --version | head -1
B=build-replay; mkdir -p $B
FLAGS="-std=c++20 -O3 -DNDEBUG -ffp-contract=off -Icore/include -Icore/src -Itests/bench -Itests/support"
if [ -f /usr/include/mpfr.h ] && [ -d /usr/include/tbb ]; then
  echo "== build with the union engine (MPFR and TBB found)"
  srcs=$(find core/src -name '*.cpp'); libs="-lmpfr -lgmp -ltbb"
else
  echo "== build without the union engine (no MPFR/TBB headers): decompose_replay_no_union.cpp stands in;"
  echo "   sets with 'shadow' above 0 are then not the same computation as on the project's build"
  srcs="core/src/footprint/decompose.cpp $(ls core/src/footprint/decompose/*.cpp) tests/bench/decompose_replay_no_union.cpp"; libs=""
fi
objs=""; pids=""
for s in $srcs tests/bench/decompose_replay.cpp; do
  o=$B/$(echo "$s" | tr / _).o
  g++ $FLAGS -c "$s" -o "$o" &
  objs="$objs $o"; pids="$pids $!"
done
wait $pids  # not a bare wait: that would wait for the tee above too, forever
g++ $objs $libs -pthread -o $B/decompose_replay || { echo "build failed"; exit 1; }
echo "== one thread (median of >= 5 passes), by size, then every core at once"
$B/decompose_replay "$DUMP" --by-size --threads "$(nproc)"
echo "== one thread again (noise check)"
$B/decompose_replay "$DUMP"

#!/bin/bash
# The CUDA backend on a GPU machine, one script per device call: tools check, build (full CMake build when
# the GIS -dev packages are there, else bench_blocks alone with nvcc: it needs only the raster
# sources), CUDA-vs-CPU tests, and blocks timings at 6k, 100k and 1M footprints on GPU and CPU.
# Logs go to $OUT (or ./gpu-out). Run from the repository root.
set -u
OUT=${OUT:-gpu-out}
mkdir -p "$OUT"
exec > >(tee "$OUT/run.log") 2>&1
export PATH=/usr/local/cuda/bin:$PATH
echo "== machine"; date -u; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv; nproc
lscpu | grep -m1 "Model name"
echo "== tools"; nvcc --version | tail -2; cmake --version | head -1; g++ --version | head -1
have_full=1
for p in gdal geos proj tbb gtest mpfr expat nlohmann_json cli11; do
  if ls /usr/include | grep -qi "^$p"; then echo "header dir for $p: yes"; else echo "header dir for $p: NO"; have_full=0; fi
done
ls /usr/include/tbb >/dev/null 2>&1 && have_tbb=1 || have_tbb=0
BENCH=""
if [ $have_full = 1 ] && command -v cmake >/dev/null; then
  echo "== full CMake build"
  cmake -S . -B build-dev -DCMAKE_BUILD_TYPE=Release -DGROUNDPLAN_CUDA=ON > "$OUT/configure.log" 2>&1 &&
    cmake --build build-dev -j"$(nproc)" --target groundplan_gpu_tests groundplan_core_tests bench_blocks > "$OUT/build.log" 2>&1
  if [ -x build-dev/bin/groundplan_gpu_tests ]; then
    BENCH=build-dev/bin/bench_blocks
    echo "== gpu tests"; build-dev/bin/groundplan_gpu_tests 2>&1 | tail -25
    echo "== core tests (raster)"; build-dev/bin/groundplan_core_tests --gtest_filter='RasterBackend*' 2>&1 | tail -5
  else
    echo "full build failed:"; tail -30 "$OUT/configure.log" "$OUT/build.log"
  fi
fi
if [ -z "$BENCH" ]; then
  echo "== standalone build (g++ + nvcc) (tbb: $have_tbb)"
  lib=""
  mkdir -p build-standalone && cd build-standalone || exit 1
  R=..; inc="-I$R/core/include -I$R/core/src -I$R/tests/support"; [ $have_tbb = 1 ] && lib="-ltbb" || inc="$inc -I$R/tests/gpu/tbb_shim"
  # .cpp with g++ as in the CMake build (nvcc's own C++ pass finds std::apply by ADL in the generators)
  # the CUDA backend is a module loaded by core (libgroundplan_cuda.so.0, found here through LD_LIBRARY_PATH)
  export LD_LIBRARY_PATH=$PWD${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  build='-DGROUNDPLAN_CUDA_MODULE_BUILD="standalone"'
  for f in core/src/blocks/cpu_raster_backend.cpp core/src/blocks/raster_common.cpp tests/support/union_generators.cpp \
           core/src/raster_backend_factory.cpp core/src/blocks/cuda_module.cpp; do
    g++ -std=c++20 -O2 -fPIC -ffp-contract=off "$build" $inc -c $R/$f -o $(basename $f).o || exit 1
  done
  nvcc -std=c++20 -O2 -arch=sm_90 --fmad=false -Xcompiler=-ffp-contract=off,-fPIC "$build" $inc -c \
    $R/gpu/src/cuda_raster_backend.cu -o cuda.o &&
  nvcc -shared -arch=sm_90 -cudart static cuda.o raster_common.cpp.o -o libgroundplan_cuda.so.0 &&
  g++ -std=c++20 -O2 $inc -c $R/tests/bench/bench_blocks.cpp -o bench.o &&
  g++ bench.o cpu_raster_backend.cpp.o raster_common.cpp.o union_generators.cpp.o raster_backend_factory.cpp.o \
    cuda_module.cpp.o $lib -ldl -o bench_blocks &&
    BENCH=build-standalone/bench_blocks
  if g++ -std=c++20 -O2 $inc -c $R/tests/gpu/cuda_raster_backend_test.cpp -o gput.o &&
     g++ gput.o cpu_raster_backend.cpp.o raster_common.cpp.o union_generators.cpp.o raster_backend_factory.cpp.o \
       cuda_module.cpp.o $lib -ldl -lgtest -lgtest_main -pthread -o gpu_tests; then
    echo "== gpu tests (standalone)"; ./gpu_tests 2>&1 | tail -25
  else echo "gpu tests: no gtest library to link"; fi
  cd ..
fi
[ -n "$BENCH" ] || { echo "no build"; exit 1; }
echo "== blocks: GPU (with --check against the CPU), then CPU"
for n in 6000 100000 1000000; do
  $BENCH --n $n --device cuda --runs 7 --check
  $BENCH --n $n --device cpu --runs 3
done
echo "== another 1M city"
$BENCH --n 1000000 --device cuda --runs 3 --check --seed 2

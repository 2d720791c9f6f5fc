# Sourced by the build scripts (run-tests.sh, run-sanitizer-tests.sh, tests/fuzz/build-and-run.sh): cmake flags
# that compile through ccache when it is installed, so that a CI machine that keeps its cache (~/.cache/ccache)
# compiles only what changed. CCACHE_BASEDIR makes paths relative to the source tree: a fresh clone elsewhere
# still hits the cache (and CCACHE_NOHASHDIR the same for -g builds: only the debug info's compile folder is off).
ccache_flags=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
  ccache_flags=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache
                -DCMAKE_CUDA_COMPILER_LAUNCHER=ccache)
fi

#!/usr/bin/env bash
# Installs every Debian package that groundplan's build, tests and demo need. Idempotent and quiet;
# run as root (or it re-runs itself with sudo) on Debian bookworm. Usage: bash packaging/install-deps.sh
set -euo pipefail

packages=(
  # toolchain; ccache: CI's three builds (Release, sanitizers, fuzz) compile only what changed since the last run
  build-essential cmake ninja-build pkg-config ccache
  # GIS stack: GDAL (OGR driver, ogr2ogr parser, output formats), GEOS (reference union),
  # PROJ (coordinate systems), GeographicLib (local frames of KML/COLLADA models)
  libgdal-dev gdal-bin python3-gdal libgeos-dev libproj-dev proj-data proj-bin libgeographiclib-dev
  # exact arithmetic (last rung of the precision ladder)
  libmpfr-dev libgmp-dev
  # formats: streaming XML (CityGML, KML, COLLADA), glTF
  libexpat1-dev libtinygltf-dev
  # compressed glTF (glTF inputs and 3D Tiles contents): Draco and meshopt decoders
  libdraco-dev libmeshoptimizer-dev
  # CityGML files and chunks of up to 64 MiB parsed in memory, 4-5x expat's speed (issue 14)
  libpugixml-dev
  # CityJSON / CityJSONSeq (issue 16)
  libsimdjson-dev
  # CLI parsing, JSON (--stats), thread pool
  libcli11-dev nlohmann-json3-dev libtbb-dev
  # GeoPackage spatial index packed by the CLI (GDAL's own SQLite)
  libsqlite3-dev
  # the CLI's allocator: jemalloc (fewer CPU seconds than glibc's malloc on many threads; optional, GROUNDPLAN_JEMALLOC)
  libjemalloc-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev python3-pytest
  # the GeoPandas/Shapely baseline of the OGR-input benchmark (issue 22, tests/bench/ogr_input_bench.sh)
  python3-geopandas
  # Boost.Polygon headers: an anchor of the union benchmark only (bench_union --engine boost, tests/bench/union_anchors.sh)
  libboost-dev
  # the Python module (issue 23, python/): pybind11 and the headers to build it; Shapely, GeoPandas (Fiona,
  # pyproj) for its wrapper and tests. Debian bookworm has no pyogrio: its test skips.
  python3-dev pybind11-dev python3-shapely python3-fiona python3-pyproj python3-numpy
  # cython3: to build Shapely 2.0 from its source for the module's tests with Shapely 2 (bookworm packages 1.8;
  # tests/python/build_shapely2.sh, -DGROUNDPLAN_SHAPELY2_DIR)
  cython3
  # QGIS as a client (issue 18, qgis/ and tests/e2e/test_qgis*.py): PyQGIS and the OGR provider to load and
  # render the driver's layers, qgis for qgis_process (runs the Processing algorithm), xvfb for headless runs
  python3-qgis qgis-providers qgis xvfb
  # MPI (issue 15, GROUNDPLAN_MPI=AUTO|ON|OFF): `mpirun -np N groundplan ...` spreads the tiled run over
  # ranks, tests/e2e/test_mpi.py runs it; Open MPI is the MPI CMake's AUTO looks for
  openmpi-bin libopenmpi-dev
  # a PostGIS server for the test of MPI ranks writing into one PostgreSQL database side by side (issue 15
  # stage 5, tests/e2e/test_postgis.py starts it on a temporary folder, local socket only; psql comes with postgresql)
  postgresql postgresql-15-postgis-3
  # fuzzing (libFuzzer with clang; tests/fuzz) and the sanitizer runtime's symbolizer
  clang libclang-rt-14-dev llvm
)

if [ "$(id -u)" -ne 0 ]; then
  exec sudo -E bash "$0" "$@"
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"

#!/usr/bin/env bash
# Builds the Debian package groundplan_<version>_<arch>.deb in the build folder (default build-deb): the CLI,
# the GDAL plugin, libgroundplan, the Python module, the QGIS plugin, the man page and, where the CUDA toolkit
# is found, the CUDA raster backend as a module loaded only when asked for (the package installs and runs
# without CUDA). Its Depends come from what the binaries link (dpkg-shlibdeps).
# Usage: bash packaging/build-deb.sh [build-folder]; then: apt-get install ./build-deb/groundplan_*.deb
# Extra CMake settings go through CMAKE_ARGS, e.g. CMAKE_ARGS=-DGROUNDPLAN_CUDA=OFF for a package without CUDA.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-deb}
bash packaging/install-deps.sh
# shellcheck disable=SC2086
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
  -DGROUNDPLAN_BUILD_TESTS=OFF -DGROUNDPLAN_BUILD_BENCH=OFF ${CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j"$(nproc)"
(cd "$build" && cpack -G DEB)
ls "$build"/groundplan_*.deb

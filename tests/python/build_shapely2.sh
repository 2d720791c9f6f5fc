#!/bin/bash
# Builds Shapely 2.0.x in place from a source tree (a checkout or `git archive` of a 2.0 tag), against Debian's
# GEOS, NumPy and cython3 (packaging/install-deps.sh), without pip or network: the module's tests then also run
# with Shapely 2 (configure with -DGROUNDPLAN_SHAPELY2_DIR=THAT_DIR; ctest -R python). About a minute.
# Usage: tests/python/build_shapely2.sh SHAPELY_SOURCE_DIR
set -eu
SRC=${1:?a Shapely 2.0.x source tree}
cd "$SRC"
nice /usr/bin/python3 setup.py build_ext -j 2 --inplace >build_ext.log 2>&1 || { tail -20 build_ext.log; exit 1; }
PYTHONPATH=$PWD /usr/bin/python3 -c "import shapely; print('Shapely', shapely.__version__, 'GEOS', shapely.geos_version_string, 'in', shapely.__file__)"

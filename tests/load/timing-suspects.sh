#!/usr/bin/env bash
# The tests that once depended on timing or that were seen failing under load, once each: the QGIS algorithm's
# cancellation, PostGIS (one process and MPI ranks), the Python module's progress / cancel / Ctrl-C, and the C++
# hostile-input, rank, chunk and cancel tests. Meant for tests/load/run-under-load.sh:
#   bash tests/load/run-under-load.sh 5 bash tests/load/timing-suspects.sh [BUILD_DIR]
set -u
cd "$(dirname "$0")/../.."
build=$(cd "${1:-build}" && pwd)
export GROUNDPLAN_BIN=$build/bin/groundplan GDAL_DRIVER_PATH=$build/gdalplugins GROUNDPLAN_SOURCE_DIR=$PWD \
  GROUNDPLAN_BUILD_DIR=$build
rc=0
/usr/bin/python3 -m pytest -q -p no:cacheprovider tests/e2e/test_qgis.py -k cancelled || rc=1
/usr/bin/python3 -m pytest -q -p no:cacheprovider tests/e2e/test_postgis.py || rc=1
PYTHONPATH=$build/python /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python/test_progress_cancel.py || rc=1
"$build/bin/groundplan_gis_tests" --gtest_filter='*Hostile*:TiledRunOverRanks.*:Pipeline.CancelStopsTheWork:Chunked*' || rc=1
"$build/bin/groundplan_core_tests" --gtest_filter='UnionTotalApi.*' || rc=1
exit $rc

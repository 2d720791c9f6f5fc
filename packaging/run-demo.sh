#!/usr/bin/env bash
# Sets up (dependencies, build) and runs the main job on the bundled sample: ground plans of 657
# buildings of Niiza (Saitama, Japan; PLATEAU CityGML 2.0) into plans.gpkg, with a summary and a
# check against GEOS UnaryUnion. Usage: bash packaging/run-demo.sh [output.gpkg]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-plans.gpkg}
bash packaging/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target groundplan ogr_GroundPlan >/dev/null
build/bin/groundplan -overwrite --verify -f GPKG "$out" sample_data/plateau-niiza/53395404_bldg_6697_op.gml \
  ground_plans footprints problems
echo "run-demo: wrote $out (layers ground_plans, footprints, problems); try: ogrinfo -so $out ground_plans"

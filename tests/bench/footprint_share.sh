#!/usr/bin/env bash
# Issue 21: the footprint stage is never the slow one (goal: decomposition <= 20 % of reading) on every real
# input, the COLLADA models included. Instruction counts (callgrind), not wall-clock, so that a loaded
# machine gives the same figures: `groundplan --threads 1 --footprints decompose` per input under
# callgrind; D = inclusive instructions of footprint::decompose_footprint (every building), R = inclusive
# instructions of gis::read_any less the footprints the reader made itself (FootprintMaker::make called
# from FootprintMaker::add: with one thread, past 16 pending tasks the reader makes them inline).
# Usage: tests/bench/footprint_share.sh [BUILD_DIR] [INPUT ...]  (default: build, every real sample)
set -euo pipefail
BUILD=${1:-build}; shift || true
D=../shared/data
if [ $# -eq 0 ]; then
  set -- $D/kml-collada-macky-google/macky-normal.kmz $D/kml-collada-macky-google/model-macky.kmz \
    "$D/kml-collada-macky-google/standalone_dae/cu_macky/CU Macky.dae" $D/kml-collada-macky-google/shared-textures.kmz \
    $D/kml-collada-korea-mago/sample-kml $D/citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml \
    sample_data/tum-main-entrance/TUM-Main-Entrance.gml $D/citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml \
    $D/citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD3-KIT-IAI-KHH-B36-V1__v3.gml $D/citygml-citygml4j-samples/lod2_buildings_v3.gml \
    $D/citygml-citygml4j-samples/lod3_building_v2.gml $D/citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml \
    $D/citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml $D/citygml1-niedersachsen-lod1-4tiles/LoD1_24085860_2_2021-01-25.gml \
    $D/cityjson-3dbag-cjseq/*.jsonl
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '%-58s %14s %14s %7s\n' input "decompose (Ir)" "read (Ir)" "D/R"
for f in "$@"; do
  [ -e "$f" ] || continue
  extra=()
  case "$f" in *.dae) extra=(--origin 127,37) ;; esac
  rm -rf "$tmp/out" "$tmp/cg"
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg" "$BUILD/bin/groundplan" -q --threads 1 -f CSV "$tmp/out" "$f" \
    --footprints decompose "${extra[@]}" >/dev/null 2>&1 || true
  callgrind_annotate --threshold=100 --tree=caller --inclusive=yes "$tmp/cg" 2>/dev/null > "$tmp/tree" || true
  python3 - "$f" "$tmp/tree" <<'PY'
import re, sys
name, tree = sys.argv[1], open(sys.argv[2]).read().splitlines()
num = lambda l: int(re.match(r'\s*([\d,]+)', l).group(1).replace(',', ''))
fn = lambda l: l.split('???:', 1)[1] if '???:' in l else ''  # the function a line names
D = R = nested = 0
for i, l in enumerate(tree):
    if re.match(r'\s*[\d,]+ \([ \d.]+%\)\s+\*', l):
        if fn(l).startswith('groundplan::footprint::decompose_footprint('): D = max(D, num(l))  # not its lambdas
        if fn(l).startswith('groundplan::gis::read_any('): R = max(R, num(l))
        if fn(l).startswith('groundplan::gis::detail::(anonymous namespace)::FootprintMaker::make('):
            j = i - 1
            while j >= 0 and re.match(r'\s*[\d,]+ \([ \d.]+%\)\s+<', tree[j]):
                if fn(tree[j]).startswith('groundplan::gis::detail::(anonymous namespace)::FootprintMaker::add('): nested += num(tree[j])
                j -= 1
R -= nested
short = name if len(name) <= 58 else '...' + name[-55:]
print('%-58s %14s %14s %6.1f%%' % (short, format(D, ','), format(R, ','), 100.0 * D / R if R else float('nan')))
PY
done

#!/bin/bash
# The CLI end to end on a GPU host (issue 4's open point: --device cuda had only been run through
# bench_blocks there). The CLI comes packed by tests/gpu/pack_cli.sh (the host has no GDAL); each
# input is run with --device cpu and --device cuda, outputs compared byte for byte, stage times
# from --stats; the CUDA run of each also with --verify (GEOS UnaryUnion; exit 3 on a mismatch).
# A large city is made there by tests/bench/gen_big_citygml.py. Usage, from the repository root:
#   tests/gpu/e2e_on_gpu.sh BUNDLE.tar.xz [BIG_MB]
set -u
BUNDLE=${1:?BUNDLE}; BIG_MB=${2:-150}
OUT=${OUT:-gpu-e2e-out}; mkdir -p "$OUT"
exec > >(tee "$OUT/e2e.log") 2>&1
W=/tmp/gp-e2e
source "$(dirname "$0")/./unpack_bundle.sh"
echo "== machine"; date -u; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc; lscpu | grep -m1 "Model name"
$G/bin/groundplan --version || { echo "the packed CLI does not start:"; ldd $G/bin/groundplan | grep "not found"; exit 1; }
echo "== a large city: tests/bench/gen_big_citygml.py $BIG_MB MB"
python3 tests/bench/gen_big_citygml.py "$W/big.gml" "$BIG_MB" | tail -2
inputs=("$G"/data/* "$W/big.gml")
summary() {  # stats JSON -> one line
  python3 - "$1" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
t = d.get("timings_s", {}); c = d.get("counts", {})
dev = {k: v for k, v in d.items() if "device" in k.lower() or "backend" in k.lower()}
print("  buildings %s plans %s problems %s | read %.3f footprints %.3f blocks %.3f union %.3f write %.3f s | %s" % (
    c.get("buildings"), c.get("ground_plans"), c.get("problems"), t.get("read", 0), t.get("footprints", 0),
    t.get("blocks", 0), t.get("union", 0), t.get("write", 0), dev))
PY
}
fail=0
for in in "${inputs[@]}"; do
  name=$(basename "$in"); echo "== $name"
  for dev in cpu cuda; do
    rm -f "$W/$name.$dev.csv"
    s=$(date +%s%N)
    $G/bin/groundplan -q -f CSV -lco GEOMETRY=AS_WKT "$W/$name.$dev.csv" "$in" --device $dev --stats "$W/$name.$dev.json"
    rc=$?; e=$(date +%s%N)
    printf "%-5s rc %d  wall %d ms\n" $dev $rc $(( (e - s) / 1000000 ))
    [ -f "$W/$name.$dev.json" ] && summary "$W/$name.$dev.json"
    [ $rc = 0 ] || fail=1
  done
  if cmp -s "$W/$name.cpu.csv" "$W/$name.cuda.csv"; then echo "  cpu and cuda outputs: identical ($(wc -l < "$W/$name.cpu.csv") lines)"
  else echo "  cpu and cuda outputs: DIFFERENT"; diff <(sort "$W/$name.cpu.csv") <(sort "$W/$name.cuda.csv") | head -5; fail=1; fi
  $G/bin/groundplan -q -f CSV -lco GEOMETRY=AS_WKT "$W/$name.auto.csv" "$in" --stats "$W/$name.auto.json"
  echo "default (--device auto): rc $? $(summary "$W/$name.auto.json")"
  $G/bin/groundplan -q -f CSV -lco GEOMETRY=AS_WKT "$W/$name.verify.csv" "$in" --device cuda --verify > "$W/$name.verify.log" 2>&1
  echo "  --device cuda --verify: exit $? $(tail -1 "$W/$name.verify.log")"
done
echo "== done (fail=$fail)"
exit $fail

#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Issue 15: peak RSS of one process (--tiles off) against the tiled run (--tiles on) on a generated tiled city
# (gen_tiled_city.py), and that both give the same plans (sorted WKT + building ids of ground_plans as CSV).
# Usage: tiles_memory_bench.sh CITY_DIR [THREADS]   (groundplan from $GROUNDPLAN_BIN, else build/bin/groundplan)
# COMPARE=0: the plans go to /vsistdout/ (discarded) and only the counts of the two modes are compared (a city
# whose CSV would not fit the disk, or whose sorted comparison would take longer than the runs).
# Prints one line a mode: peak RSS, user+sys CPU, wall, plans, and the --stats "tiles" section of the tiled run.
set -euo pipefail
city=$1
threads=${2:-2}
here=$(cd "$(dirname "$0")" && pwd)
bin=${GROUNDPLAN_BIN:-$here/../../build/bin/groundplan}
export GDAL_DRIVER_PATH=${GDAL_DRIVER_PATH:-$(dirname "$bin")/../gdalplugins}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
files=$(ls "$city" | wc -l)
bytes=$(du -sbL "$city" | cut -f1)
echo "city: $city, $files files, $bytes bytes, threads $threads"
compare=${COMPARE:-1}
for mode in off on; do
  dst="$work/out_$mode"
  [ "$compare" = 0 ] && dst=/vsistdout/
  /usr/bin/time -f "%M %U %S %e" -o "$work/time_$mode" \
    "$bin" -q --tiles "$mode" --threads "$threads" --stats "$work/stats_$mode.json" \
    -f CSV -lco GEOMETRY=AS_WKT "$dst" "$city" ground_plans > /dev/null
  read -r rss_kb user sys wall < "$work/time_$mode"
  python3 - "$work/stats_$mode.json" "$mode" "$rss_kb" "$user" "$sys" "$wall" "$files" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); mode = sys.argv[2]; rss = int(sys.argv[3]) / 1024; files = int(sys.argv[7])
b = s["counts"]["buildings"]
print(f"tiles {mode}: peak RSS {rss:.0f} MiB ({rss * 1048576 / b:.0f} B/building, {rss / files:.1f} MiB/tile), "
      f"CPU {float(sys.argv[4]) + float(sys.argv[5]):.1f} s, wall {float(sys.argv[6]):.1f} s, buildings {b}, "
      f"plans {s['counts']['ground_plans']}")
if "tiles" in s:
    print("  tiles:", json.dumps(s["tiles"]))
PY
  if [ "$compare" = 0 ]; then
    python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['counts']; print(c['buildings'], c['ground_plans'], c.get('problems'))" \
      "$work/stats_$mode.json" > "$work/hash_$mode"
    echo "  counts (buildings, plans, problems): $(cat "$work/hash_$mode")"
    continue
  fi
  # the plans as a sorted set (the tiled run writes final plans first, and a ring may start at another vertex:
  # rings are compared as vertex cycles rotated to their smallest vertex, holes sorted): the same in both modes
  python3 -c "
import csv, sys, hashlib
csv.field_size_limit(1 << 30)
def cycle(t):
    p = t.strip().split(',')[:-1]
    k = min(range(len(p)), key=lambda i: tuple(map(float, p[i].split())))
    return tuple(p[k:] + p[:k])
def key(w):
    r = [cycle(x) for x in w[len('POLYGON (('):-2].split('),(')]
    return r[0], tuple(sorted(r[1:]))
rows = sorted((key(r['WKT']), r['n_parts'], r['area_m2'], r['building_ids']) for r in csv.DictReader(open(sys.argv[1])))
print(hashlib.md5(repr(rows).encode()).hexdigest())" "$work/out_$mode/ground_plans.csv" > "$work/hash_$mode"
  echo "  sorted plans md5 $(cat "$work/hash_$mode")"
  rm -rf "$work/out_$mode"
done
what="same plans"
[ "$compare" = 0 ] && what="same counts"
cmp -s "$work/hash_off" "$work/hash_on" && echo "$what: yes" || { echo "$what: NO"; exit 1; }

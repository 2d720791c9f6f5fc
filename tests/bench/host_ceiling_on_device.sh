#!/bin/bash
# What the 16-core host gives to N equal pieces of pure computation, whatever our code does (issues 14 and 15):
# one single-threaded CPU loop (Python, no memory traffic to speak of) alone, then N copies started at once. The
# slowest copy against one alone bounds any "16 equal pieces" speed-up on this host (reading scaling, MPI ranks).
# Usage: tests/bench/host_ceiling_on_device.sh [N ...] (default 8 16); no bundle needed.
set -u
LOOP=$(mktemp); OUTS=$(mktemp -d)
cat > "$LOOP" <<'PY'
import time
t = time.time(); s = 0
for i in range(40_000_000): s += i
print("%.2f" % (time.time() - t))
PY
echo "one alone, s:"; for r in 1 2 3; do python3 "$LOOP"; done | tr '\n' ' '; echo
for n in "${@:-8 16}"; do
  for n1 in $n; do
    for r in 1 2; do
      for i in $(seq "$n1"); do python3 "$LOOP" > "$OUTS/$i.txt" & done; wait
      echo "$n1 at once, each s (sorted): $(cat "$OUTS"/*.txt | sort -n | tr '\n' ' ')"; rm -f "$OUTS"/*.txt
    done
  done
done
grep -m1 "model name" /proc/cpuinfo; nproc
rm -rf "$LOOP" "$OUTS"

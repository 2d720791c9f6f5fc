#!/usr/bin/env bash
# Runs a command RUNS times in a row while `stress --cpu N` keeps N cores busy, to find tests that depend on
# timing; prints each run's exit status and the number of failed runs (exit 1 if any).
# Usage: bash tests/load/run-under-load.sh RUNS COMMAND [ARGS...]   (GROUNDPLAN_LOAD_CPUS, default 2)
# stress (Debian package) is installed here, for this script only.
set -euo pipefail
cd "$(dirname "$0")/../.."
runs=$1
shift
if ! command -v stress >/dev/null 2>&1; then
  [ "$(id -u)" -eq 0 ] || { echo "run-under-load: stress is not installed (apt-get install stress, as root)"; exit 2; }
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq stress >/dev/null
fi
stress --cpu "${GROUNDPLAN_LOAD_CPUS:-2}" --quiet &
load=$!
trap 'kill "$load" 2>/dev/null; wait "$load" 2>/dev/null || true' EXIT
failed=0
for ((i = 1; i <= runs; i++)); do
  t0=$SECONDS
  if "$@" > "/tmp/run-under-load.$$.$i.log" 2>&1; then status=0; else status=$?; fi
  echo "run $i/$runs: exit $status, $((SECONDS - t0)) s (output: /tmp/run-under-load.$$.$i.log)"
  [ "$status" -eq 0 ] || failed=$((failed + 1))
done
echo "under stress --cpu ${GROUNDPLAN_LOAD_CPUS:-2}: $failed of $runs runs failed: $*"
[ "$failed" -eq 0 ]

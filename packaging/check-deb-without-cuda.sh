#!/usr/bin/env bash
# Installs the Debian package into a fresh Debian bookworm (a debootstrap chroot: no CUDA toolkit, no NVIDIA
# driver, none of the build's packages) with `apt-get install ./groundplan_*.deb`, and checks that it loads
# and works there: no libcudart anywhere, every installed binary's libraries found, the GDAL plugin
# (`ogrinfo --format GroundPlan`), the CLI (`groundplan --help`, a run with --verify), the GDAL driver through
# ogr2ogr, the Python module, the QGIS plugin's files; `--device cuda` fails with a message saying why, with the
# CUDA module present (no driver) and moved aside (the module missing), and the CPU run still works.
# Needs root, debootstrap and the network (Debian's mirror). Prints each check; exits 1 on the first failure.
# Usage: bash packaging/check-deb-without-cuda.sh build-deb/groundplan_<version>_<arch>.deb [chroot-folder]
set -euo pipefail
deb=$(realpath "$1")
root=${2:-/tmp/groundplan-deb-check}
cd "$(dirname "$0")/.."
sample=sample_data/plateau-niiza/53392547_bldg_6697_op2.gml

if [ ! -x "$root/usr/bin/apt-get" ]; then
  command -v debootstrap >/dev/null || { echo "needs debootstrap (apt-get install debootstrap)" >&2; exit 1; }
  debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian >/dev/null
fi
cp /etc/resolv.conf "$root/etc/resolv.conf"
rm -rf "$root/proof" && mkdir -p "$root/proof"
cp "$deb" "$sample" "$root/proof/"
mountpoint -q "$root/proc" || mount -t proc proc "$root/proc"
trap 'umount "$root/proc" 2>/dev/null || true' EXIT

in_root() { chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LANG=C.UTF-8 bash -c "$1"; }
fail() { echo "FAILED: $*" >&2; exit 1; }

echo "== apt-get install ./$(basename "$deb") in $root"
in_root "export DEBIAN_FRONTEND=noninteractive; apt-get update -qq && (dpkg -s groundplan >/dev/null 2>&1 && apt-get purge -y -qq groundplan || true) && cd /proof && apt-get install -y -qq ./$(basename "$deb")" \
  >"$root/proof/apt.log" 2>&1 || { tail -20 "$root/proof/apt.log"; fail "apt-get install"; }
grep -E "^Setting up groundplan" "$root/proof/apt.log"

echo "== no CUDA in the chroot"
[ -z "$(find "$root" -xdev \( -name 'libcudart*' -o -name 'libcuda.so*' \) -print -quit)" ] || fail "a CUDA library is in $root"
! ls -d "$root"/usr/local/cuda* >/dev/null 2>&1 || fail "$root/usr/local/cuda exists"
echo "no libcudart, no libcuda, no /usr/local/cuda"

echo "== every installed binary finds its libraries"
for f in $(in_root "dpkg -L groundplan" | grep -E '(/bin/groundplan|\.so[.0-9]*)$'); do
  [ -f "$root$f" ] && [ ! -L "$root$f" ] || continue
  missing=$(in_root "ldd $f" | grep -E 'not found|cudart' || true)
  [ -z "$missing" ] || fail "$f: $missing"
  echo "$f: ok"
done

echo "== the GDAL plugin and the CLI load"
out=$(in_root "ogrinfo --format GroundPlan") || fail "ogrinfo --format GroundPlan: exit status $?"
grep -E "Short Name: GroundPlan" <<<"$out" || fail "ogrinfo --format GroundPlan: $out"
out=$(in_root "groundplan --help") || fail "groundplan --help: exit status $?"
grep -m1 "ground plans" <<<"$out" || fail "groundplan --help: $out"

echo "== a run, the driver, Python"
out=$(in_root "cd /tmp && groundplan -overwrite --verify -f GPKG p.gpkg /proof/$(basename $sample) 2>&1") || fail "groundplan run: $out"
echo "$out" | grep -E "ground plans|MATCH" | cut -c1-100
in_root "cd /tmp && ogr2ogr -overwrite -f GPKG d.gpkg GROUNDPLAN:/proof/$(basename $sample) ground_plans && ogrinfo -so d.gpkg ground_plans" \
  | grep "Feature Count: 23" || fail "ogr2ogr through the driver"
in_root "python3 -c 'import groundplan; from shapely.geometry import box; r = groundplan.union([box(0, 0, 1, 1), box(1, 0, 2, 1)]); assert r.members == [[0, 1]], r.members; print(\"python: union ok\", groundplan.__file__)'" \
  || fail "python3 import groundplan"
[ -f "$root/usr/share/qgis/python/plugins/groundplan_provider/metadata.txt" ] || fail "QGIS plugin not installed"
echo "QGIS plugin: /usr/share/qgis/python/plugins/groundplan_provider"

echo "== --device cuda without a driver, then without the module"
module=$(in_root "dpkg -L groundplan" | grep '/libgroundplan_cuda.so.0$' || true)
cuda_run="cd /tmp && groundplan --device cuda -overwrite -f GPKG c.gpkg /proof/$(basename $sample) 2>&1"
if [ -n "$module" ]; then
  msg=$(in_root "$cuda_run") && fail "--device cuda succeeded without a driver"
  echo "$msg" | grep "no CUDA device answers" || fail "--device cuda: $msg"
  mv "$root$module" "$root/proof/"
  msg=$(in_root "$cuda_run") && { mv "$root/proof/$(basename $module)" "$root$module"; fail "--device cuda succeeded without the module"; }
  mv "$root/proof/$(basename $module)" "$root$module"
  echo "$msg" | grep "could not be loaded" || fail "--device cuda without the module: $msg"
else
  msg=$(in_root "$cuda_run") && fail "--device cuda succeeded in a package without CUDA"
  echo "$msg" | grep "could not be loaded" || fail "--device cuda: $msg"
fi
in_root "cd /tmp && groundplan --device auto -overwrite -f GPKG c.gpkg /proof/$(basename $sample) 2>&1" | grep "23 ground plans" \
  || fail "--device auto"
echo "all checks passed"

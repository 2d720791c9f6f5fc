#!/bin/bash
# Packs a CUDA-enabled `groundplan` CLI with the shared libraries it needs (all but the C and C++
# runtimes, which the target has in newer versions) and GDAL's and PROJ's data into one .tar.xz, so
# the end-to-end run (tests/gpu/e2e_on_gpu.sh) can happen on a GPU host that has no GDAL, GEOS or
# PROJ packages. Real inputs go in as well (data/). Usage, from the repository root:
#   tests/gpu/pack_cli.sh BUILD_DIR OUT.tar.xz INPUT...
set -eu
BUILD=${1:?BUILD_DIR}; OUTF=${2:?OUT.tar.xz}; shift 2
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
mkdir -p "$T/gp/bin" "$T/gp/lib" "$T/gp/share" "$T/gp/data"
# PACK_EXTRA_BINS: other programs to pack with it (ogr2ogr, as a baseline for the writer).
bins=("$BUILD/bin/groundplan")
for b in ${PACK_EXTRA_BINS:-}; do bins+=("$(command -v "$b")"); done
cp "${bins[@]}" "$T/gp/bin/"
for b in "${bins[@]}"; do ldd "$b"; done | awk '$3 ~ /^\// {print $3}' | sort -u | while read -r lib; do
  case "$(basename "$lib")" in
    libc.so*|libm.so*|libstdc++.so*|libgcc_s.so*|ld-linux*|libpthread.so*|libdl.so*|librt.so*|libcuda.so*) ;;
    *) cp -L "$lib" "$T/gp/lib/" ;;
  esac
done
cp -r /usr/share/gdal "$T/gp/share/gdal"
mkdir -p "$T/gp/share/proj" && cp /usr/share/proj/proj.db "$T/gp/share/proj/"
# PACK_EXTRA_LIBS: other libraries to pack (libtbbmalloc_proxy.so.2, to try TBB's allocator by LD_PRELOAD).
for l in ${PACK_EXTRA_LIBS:-}; do cp -L "$l" "$T/gp/lib/"; done
for f in "$@"; do cp -r "$f" "$T/gp/data/"; done
du -sh "$T/gp"
tar -C "$T" -cf - gp | xz -T2 -6 > "$OUTF"
ls -la "$OUTF"

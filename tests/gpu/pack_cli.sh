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
# PACK_MPI=1: Open MPI's launcher (orterun as mpirun, orted), its libraries, plugins (openmpi3/, PMIx's) and help
# texts under gp/ompi/ in the layout of their Debian prefix /usr, for OPAL_PREFIX=gp/ompi (tests/bench/mpi_on_device.sh).
if [ "${PACK_MPI:-0}" = 1 ]; then
  O=$T/gp/ompi; M=/usr/lib/x86_64-linux-gnu/openmpi; P=/usr/lib/x86_64-linux-gnu/pmix2
  mkdir -p "$O/bin" "$O/lib/x86_64-linux-gnu" "$O/share"
  cp -L /usr/bin/orterun "$O/bin/mpirun"; cp -L /usr/bin/orted "$O/bin/orted"
  cp -rL "$M" "$O/lib/x86_64-linux-gnu/openmpi"; rm -rf "$O/lib/x86_64-linux-gnu/openmpi/include"
  [ -d "$P" ] && cp -rL "$P" "$O/lib/x86_64-linux-gnu/pmix2"
  cp -r /usr/share/openmpi "$O/share/openmpi"; [ -d /usr/share/pmix ] && cp -r /usr/share/pmix "$O/share/pmix"
  # what the launcher and the plugins link beyond the C/C++ runtimes (libevent, hwloc, PMIx ...)
  for f in "$O/bin/mpirun" "$O/bin/orted" "$O"/lib/x86_64-linux-gnu/openmpi/lib/openmpi3/*.so \
           "$O"/lib/x86_64-linux-gnu/pmix2/lib/pmix/*.so; do [ -e "$f" ] && ldd "$f"; done 2>/dev/null |
    awk '$3 ~ /^\// {print $3}' | sort -u | while read -r lib; do
    case "$(basename "$lib")" in
      libc.so*|libm.so*|libstdc++.so*|libgcc_s.so*|ld-linux*|libpthread.so*|libdl.so*|librt.so*|libcuda.so*) ;;
      *) [ -e "$T/gp/lib/$(basename "$lib")" ] || cp -L "$lib" "$T/gp/lib/" ;;
    esac
  done
fi
for f in "$@"; do cp -r "$f" "$T/gp/data/"; done
du -sh "$T/gp"
tar -C "$T" -cf - gp | xz -T2 -6 > "$OUTF"
ls -la "$OUTF"

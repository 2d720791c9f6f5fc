# Sourced by the scripts that run on the GPU host (no GDAL there): unpacks the bundle of tests/gpu/pack_cli.sh
# ($BUNDLE) into an emptied $W and points the loader and GDAL/PROJ at it; $G is the unpacked tree.
rm -rf "$W"; mkdir -p "$W"
xz -dc "$BUNDLE" | tar -C "$W" -xf - || { echo "cannot unpack $BUNDLE"; exit 1; }
G=$W/gp
export LD_LIBRARY_PATH=$G/lib GDAL_DATA=$G/share/gdal PROJ_DATA=$G/share/proj PROJ_LIB=$G/share/proj

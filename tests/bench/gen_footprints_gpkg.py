#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes a GeoPackage of N 2D building footprints with overlapping parts (issue 22 benchmark), through GDAL's
own GPKG writer: rows of 10 row houses sharing party walls, each house a 9 x 10 m body and an overlapping
4 x 3 m wing, so that half the features overlap another. EPSG:25832 around (400000, 5800000).
Usage: gen_footprints_gpkg.py OUT.gpkg N"""
import sys

from osgeo import ogr, osr

out, n = sys.argv[1], int(sys.argv[2])
ogr.UseExceptions()
ds = ogr.GetDriverByName("GPKG").CreateDataSource(out)
srs = osr.SpatialReference()
srs.ImportFromEPSG(25832)
lyr = ds.CreateLayer("footprints", srs, ogr.wkbPolygon)
lyr.CreateField(ogr.FieldDefn("building", ogr.OFTInteger64))
defn = lyr.GetLayerDefn()
per_row = 10
rows_per_line = 100  # 100 rows of 10 houses side by side, then the next line of rows
lyr.StartTransaction()
for i in range(n):
    house = i // 2
    row, k = divmod(house, per_row)
    x0 = 400000 + (row % rows_per_line) * (per_row * 9 + 6) + k * 9
    y0 = 5800000 + (row // rows_per_line) * 20
    if i % 2 == 0:
        x1, y1, x0_, y0_ = x0 + 9, y0 + 10, x0, y0
    else:
        x0_, y0_, x1, y1 = x0 + 3, y0 + 8, x0 + 7, y0 + 11  # wing over the back wall
    f = ogr.Feature(defn)
    f.SetField(0, house)
    f.SetGeometryDirectly(ogr.CreateGeometryFromWkt(
        f"POLYGON (({x0_} {y0_},{x1} {y0_},{x1} {y1},{x0_} {y1},{x0_} {y0_}))"))
    lyr.CreateFeature(f)
lyr.CommitTransaction()
ds = None

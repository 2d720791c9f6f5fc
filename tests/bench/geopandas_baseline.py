#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The GeoPandas/Shapely way to the same ground plans (issue 22 benchmark baseline): read the layer,
unary_union (GEOS), explode into polygons, write a GeoPackage. Prints the seconds of each step.
Usage: geopandas_baseline.py SRC.gpkg LAYER OUT.gpkg"""
import sys
import time

import geopandas as gpd

src, layer, out = sys.argv[1:4]
t0 = time.monotonic()
df = gpd.read_file(src, layer=layer)
t1 = time.monotonic()
union = df.geometry.unary_union
t2 = time.monotonic()
plans = gpd.GeoDataFrame(geometry=[union], crs=df.crs).explode(index_parts=False).reset_index(drop=True)
t3 = time.monotonic()
plans.to_file(out, layer="ground_plans", driver="GPKG")
t4 = time.monotonic()
print(f"features={len(df)} plans={len(plans)} read_s={t1 - t0:.2f} union_s={t2 - t1:.2f} explode_s={t3 - t2:.2f} "
      f"write_s={t4 - t3:.2f} total_s={t4 - t0:.2f}")

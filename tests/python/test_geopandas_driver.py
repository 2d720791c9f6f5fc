# SPDX-License-Identifier: MIT
"""GeoPandas through GDAL: geopandas.read_file("GROUNDPLAN:...") with the plugin (Fiona; pyogrio where installed)."""
import os
import subprocess
import sys

import pytest

from conftest import BUILD_DIR, PLATEAU, PLUGIN_DIR, groundplan

pytest.importorskip("geopandas")

# Fiona reads GDAL_DRIVER_PATH when it registers GDAL's drivers: a process of its own with it set.
FIONA = """
import sys, fiona, geopandas
fiona.supported_drivers["GroundPlan"] = "r"   # the one line Fiona needs: it lists the drivers it may use
path = sys.argv[1]
for layer in ("ground_plans", "footprints", "problems"):
    df = geopandas.read_file("GROUNDPLAN:" + path, layer=layer)
    ids = list(df["gp_id"]) if "gp_id" in df else []
    print(layer, len(df), df.crs.to_epsg() if getattr(df, "crs", None) else None, sum(x == x for x in ids))
"""

PYOGRIO = """
import sys, geopandas
for layer in ("ground_plans", "footprints", "problems"):
    df = geopandas.read_file("GROUNDPLAN:" + sys.argv[1], layer=layer, engine="pyogrio")
    ids = list(df["gp_id"]) if "gp_id" in df else []
    print(layer, len(df), df.crs.to_epsg() if getattr(df, "crs", None) else None, sum(x == x for x in ids))
"""


def expected():
    r = groundplan.read(PLATEAU)
    epsg = r.plans.crs.to_epsg()
    return [
        f"ground_plans {len(r.plans)} {epsg} {len(r.plans)}",
        f"footprints {len(r.footprints)} {epsg} {int(r.footprints['gp_id'].notna().sum())}",
        f"problems {len(r.problems)} None 0",
    ]


def run_script(script):
    env = dict(os.environ, GDAL_DRIVER_PATH=PLUGIN_DIR)
    p = subprocess.run([sys.executable, "-c", script, str(PLATEAU)], env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return p.stdout.split("\n")[:3]


def test_geopandas_read_file_through_fiona():
    pytest.importorskip("fiona")
    assert run_script(FIONA) == expected()


def test_geopandas_read_file_through_pyogrio():
    pytest.importorskip("pyogrio", reason="pyogrio is not installed (Debian bookworm does not package it)")
    assert run_script(PYOGRIO) == expected()

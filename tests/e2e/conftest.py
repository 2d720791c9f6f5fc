# SPDX-License-Identifier: MIT
"""Fixtures for the end-to-end tests: the built CLI and plugin, sample paths, GDAL with our driver."""
import os
import pathlib
import subprocess

import pytest
from osgeo import gdal, ogr

gdal.UseExceptions()

SOURCE_DIR = pathlib.Path(os.environ.get("GROUNDPLAN_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
BIN = os.environ.get("GROUNDPLAN_BIN", str(SOURCE_DIR / "build" / "bin" / "groundplan"))
PLUGIN_DIR = os.environ.get("GDAL_DRIVER_PATH", str(SOURCE_DIR / "build" / "gdalplugins"))
SHARED_DATA = pathlib.Path(os.environ.get("GROUNDPLAN_SHARED_DATA_DIR", SOURCE_DIR.parent / "shared" / "data"))
SAMPLES = SOURCE_DIR / "sample_data"

PLATEAU = SAMPLES / "plateau-niiza" / "53395404_bldg_6697_op.gml"
PLATEAU_SMALL = SAMPLES / "plateau-niiza" / "53392547_bldg_6697_op2.gml"
LORUP = SAMPLES / "niedersachsen-lorup" / "LoD1_24065862_2_2021-01-25.gml"
TUM = SAMPLES / "tum-main-entrance" / "TUM-Main-Entrance.gml"
BERLIN = SHARED_DATA / "citygml1-berlin-lod2-libcitygml" / "berlin_open_data_sample_data.citygml"


def gdal_env():
    env = dict(os.environ)
    env["GDAL_DRIVER_PATH"] = PLUGIN_DIR
    return env


def run(args, check=True):
    """Runs a command; returns CompletedProcess with text output. Fails the test with the output on error."""
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True, env=gdal_env(), timeout=600)
    if check and p.returncode != 0:
        pytest.fail(f"{' '.join(map(str, args))} exited {p.returncode}\nstdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p


@pytest.fixture(scope="session", autouse=True)
def register_plugin():
    """Loads our plugin into this Python process's GDAL, as QGIS or a pipeline script would."""
    gdal.SetConfigOption("GDAL_DRIVER_PATH", PLUGIN_DIR)
    gdal.AllRegister()
    assert gdal.GetDriverByName("GroundPlan") is not None, f"plugin not found in {PLUGIN_DIR}"


def layer_rows(path, layer_name):
    """[(fields dict, geometry WKB)] of a layer, ordered by FID."""
    ds = ogr.Open(str(path))
    assert ds is not None, path
    lyr = ds.GetLayerByName(layer_name)
    assert lyr is not None, f"{path} has no layer {layer_name}"
    rows = []
    for f in lyr:
        g = f.GetGeometryRef()
        rows.append((f.items(), g.ExportToIsoWkb() if g else None))
    return rows

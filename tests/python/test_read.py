# SPDX-License-Identifier: MIT
"""groundplan.read against the CLI's GeoPackage (the same pipeline, the same features), errors, records."""
import math
import os
import subprocess
import sys

import pytest

from conftest import BIN, BUILD_DIR, PLATEAU, PLATEAU_SMALL, LORUP, PLUGIN_DIR, groundplan

ogr = pytest.importorskip("osgeo.ogr")


def cli_gpkg(tmp_path, inputs, *flags):
    out = tmp_path / "out.gpkg"
    cmd = [BIN, *flags, "-f", "GPKG", str(out), str(inputs), "ground_plans", "footprints", "problems"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=dict(os.environ, GDAL_DRIVER_PATH=PLUGIN_DIR))
    assert p.returncode == 0, p.stderr
    return out


def gpkg_rows(path, layer):
    ds = ogr.Open(str(path))
    lyr = ds.GetLayerByName(layer)
    assert lyr is not None, layer
    rows = []
    for f in lyr:
        g = f.GetGeometryRef()
        rows.append((f.items(), g.ExportToIsoWkb() if g else None))
    srs = lyr.GetSpatialRef()
    return rows, srs


def same_value(a, b):
    if a is None or (isinstance(a, float) and math.isnan(a)):
        return b is None or (isinstance(b, float) and math.isnan(b))
    if isinstance(a, float) or isinstance(b, float):
        return b is not None and a == pytest.approx(b, rel=1e-12, abs=1e-12)
    return a == b


def compare(frame, rows, has_geometry):
    from shapely import wkb

    assert len(frame) == len(rows)
    for i, (fields, geom) in enumerate(rows):
        rec = frame.iloc[i]
        for k, v in fields.items():
            got = rec[k]
            got = None if got is None or (isinstance(got, float) and math.isnan(got)) else (got.item() if hasattr(got, "item") else got)
            assert same_value(v, got), f"row {i} field {k}: CLI {v!r}, read() {got!r}"
        if has_geometry:
            ref = wkb.loads(bytes(geom))
            assert rec.geometry.equals_exact(ref, 0), f"row {i}: geometries differ"


@pytest.mark.parametrize("inputs,flags", [
    ([PLATEAU], []),
    ([PLATEAU_SMALL, LORUP], ["--preset", "cfd"]),  # a folder of two files in two CRSs, a level of detail
])
def test_read_matches_cli_geopackage(tmp_path, inputs, flags):
    pytest.importorskip("geopandas")
    if len(inputs) == 1:
        inputs = inputs[0]
    else:
        folder = tmp_path / "in"
        folder.mkdir()
        for f in inputs:
            (folder / f.name).symlink_to(f)
        inputs = folder
    gpkg = cli_gpkg(tmp_path, inputs, *flags)
    options = {"preset": flags[1]} if flags else {}
    r = groundplan.read(inputs, **options)
    for frame, layer, geom in ((r.plans, "ground_plans", True), (r.footprints, "footprints", True), (r.problems, "problems", False)):
        rows, srs = gpkg_rows(gpkg, layer)
        compare(frame, rows, geom)
        if geom:
            assert frame.crs is not None
            from pyproj import CRS

            assert CRS(frame.crs).equals(CRS.from_wkt(srs.ExportToWkt())), layer
    assert r.stats["buildings_read"] == len(r.footprints) + r.stats["buildings_dropped"]


def test_read_options_and_level_of_detail():
    exact = groundplan.read(PLATEAU_SMALL)
    cfd = groundplan.read(PLATEAU_SMALL, preset="cfd", threads=1)
    assert len(cfd.plans) <= len(exact.plans)
    assert set(cfd.footprints.columns) == set(exact.footprints.columns)
    assert (cfd.problems["stage"] == "lod").any() or len(cfd.plans) < len(exact.plans)  # the preset did something
    both = groundplan.read([PLATEAU_SMALL, LORUP])  # a list of inputs
    assert len(both.footprints) == len(exact.footprints) + len(groundplan.read(LORUP).footprints)


def test_read_errors_carry_the_cli_messages(tmp_path):
    with pytest.raises(OSError, match="no-such-file.gml"):
        groundplan.read(tmp_path / "no-such-file.gml")
    with pytest.raises(ValueError, match="SNAP=abc"):
        groundplan.read(PLATEAU_SMALL, snap="abc")
    with pytest.raises(ValueError, match="footprints|FOOTPRINTS|sideways"):
        groundplan.read(PLATEAU_SMALL, footprints="sideways")
    with pytest.raises(TypeError, match="frobnicate"):
        groundplan.read(PLATEAU_SMALL, frobnicate=1)


def test_read_without_geopandas_gives_records():
    code = (
        "import sys; sys.modules['geopandas'] = None\n"
        "import groundplan\n"
        f"r = groundplan.read({str(PLATEAU_SMALL)!r})\n"
        "assert isinstance(r.plans, list) and isinstance(r.plans[0], dict), type(r.plans)\n"
        "assert r.plans[0]['geometry'].geom_type == 'Polygon'\n"
        "assert {'fp_id', 'source_id', 'gp_id', 'geometry'} <= set(r.footprints[0])\n"
        "assert r.crs\n"
    )
    env = dict(os.environ, PYTHONPATH=str(BUILD_DIR / "python"))
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr

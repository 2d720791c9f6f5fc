# SPDX-License-Identifier: MIT
"""End to end: real CityGML through both routes (the CLI and ogr2ogr with the plugin), checked against
GEOS UnaryUnion of the same footprints (through OGR's GEOS binding, independent of our C++ check)."""
import json

import pytest
from osgeo import gdal, ogr

from conftest import BERLIN, BIN, LORUP, PLATEAU, PLATEAU_SMALL, SHARED_DATA, TUM, layer_rows, run, thirdparty_data

SAMPLES = [PLATEAU_SMALL, PLATEAU, LORUP, TUM, pytest.param(BERLIN, marks=thirdparty_data)]


def test_plugin_is_listed_with_its_open_options():
    formats = run(["ogrinfo", "--formats"]).stdout
    assert "GroundPlan" in formats
    doc = run(["ogrinfo", "--format", "GroundPlan"]).stdout
    for option in ("RESOLUTION", "DEVICE", "FOOTPRINTS", "LOD", "T_SRS", "ORIGIN"):
        assert option in doc
    assert "GROUNDPLAN:" in doc  # the connection prefix


def test_cli_and_ogr2ogr_give_the_same_plans(tmp_path):
    a, b = tmp_path / "cli.gpkg", tmp_path / "ogr2ogr.gpkg"
    run([BIN, "-f", "GPKG", a, PLATEAU])
    run(["ogr2ogr", "-f", "GPKG", b, f"GROUNDPLAN:{PLATEAU}", "ground_plans"])
    rows_a, rows_b = layer_rows(a, "ground_plans"), layer_rows(b, "ground_plans")
    assert len(rows_a) > 100
    assert rows_a == rows_b


def test_python_vector_translate():
    out = "/vsimem/plans.gpkg"
    ds = gdal.VectorTranslate(out, f"GROUNDPLAN:{PLATEAU_SMALL}", format="GPKG", layers=["ground_plans"])
    assert ds is not None
    assert ds.GetLayerByName("ground_plans").GetFeatureCount() > 0
    ds = None
    gdal.Unlink(out)


def _polygons(g):
    """The polygons of a geometry (MakeValid may return collections with lines: they have no area)."""
    t = ogr.GT_Flatten(g.GetGeometryType())
    if t == ogr.wkbPolygon:
        return [g.Clone()]
    if t in (ogr.wkbMultiPolygon, ogr.wkbGeometryCollection):
        return [p for i in range(g.GetGeometryCount()) for p in _polygons(g.GetGeometryRef(i).Clone())]
    return []


def _union_of_footprints(path):
    """GEOS union (via OGR) of every footprint polygon, each polygon made valid on its own first (a
    building's ground polygons may overlap each other: MakeValid on the whole MultiPolygon would XOR them)."""
    ds = ogr.Open(str(path))
    parts = []
    for f in ds.GetLayerByName("footprints"):
        for p in _polygons(f.GetGeometryRef()):
            parts.extend(_polygons(p if p.IsValid() else p.MakeValid()))
    bag = ogr.Geometry(ogr.wkbMultiPolygon)
    for p in parts:
        bag.AddGeometry(p)
    return bag.UnionCascaded()  # one GEOS cascaded union, as UnaryUnion; pairwise unions add rounding slivers


@pytest.mark.parametrize("sample", SAMPLES, ids=lambda p: p.name)
def test_plans_equal_geos_unary_union(tmp_path, sample):
    out = tmp_path / "plans.gpkg"
    stats = tmp_path / "stats.json"
    run([BIN, "--stats", stats, "-f", "GPKG", out, sample, "ground_plans", "footprints", "problems"])

    ds = ogr.Open(str(out))
    plans = ds.GetLayerByName("ground_plans")
    assert plans.GetSpatialRef() is not None, "layer CRS missing"
    assert plans.GetSpatialRef().IsProjected()
    ours = ogr.Geometry(ogr.wkbMultiPolygon)
    holes = 0
    for f in plans:
        g = f.GetGeometryRef()
        assert g.GetGeometryType() == ogr.wkbPolygon
        assert g.IsValid(), f"plan {f['gp_id']} invalid"
        # Attributes agree with the geometry and with each other.
        assert f["area_m2"] == pytest.approx(g.GetArea(), rel=1e-9)
        assert f["n_parts"] == len(f["building_ids"].split(","))
        holes += g.GetGeometryCount() - 1
        ours.AddGeometry(g)
    ref = _union_of_footprints(out)
    ref_polys = _polygons(ref)
    assert ours.GetGeometryCount() == len(ref_polys)
    assert holes == sum(p.GetGeometryCount() - 1 for p in ref_polys)
    symdiff = ours.UnionCascaded().SymDifference(ref).GetArea()
    assert symdiff <= 1e-9 * ref.GetArea(), f"symmetric difference {symdiff} m2 of {ref.GetArea()} m2"

    # Nothing lost: every building read is a footprint or a problem; every footprint is in a plan.
    counts = json.loads(stats.read_text())["counts"]
    assert counts["ground_plans"] == ours.GetGeometryCount()
    problems = [f.items() for f in ds.GetLayerByName("problems")]
    per_building = [p for p in problems if p["source_id"] and p["code"] != "NOTE"]
    assert counts["buildings"] == counts["footprints"] + len(per_building)
    union_problems = {p["source_id"] for p in problems if p["stage"] == "union"}
    for f in ds.GetLayerByName("footprints"):
        assert f["gp_id"] is not None or f["source_id"] in union_problems, f["source_id"]


def test_verify_flag_reports_a_match(tmp_path):
    p = run([BIN, "--verify", "-f", "GPKG", tmp_path / "v.gpkg", PLATEAU_SMALL])
    assert "MATCH" in p.stdout and "MISMATCH" not in p.stdout


def test_ogrinfo_summary_of_the_plugin_layers():
    out = run(["ogrinfo", "-so", f"GROUNDPLAN:{PLATEAU_SMALL}", "ground_plans"]).stdout
    assert "Feature Count:" in out
    assert "gp_id: Integer64" in out
    assert "UTM zone 54N" in out  # EPSG:6697 lat/lon goes to the UTM zone of Tokyo


def test_open_options_reach_the_pipeline():
    p = run(["ogrinfo", "-so", "-oo", "DEVICE=nonsense", f"GROUNDPLAN:{PLATEAU_SMALL}"], check=False)
    assert p.returncode != 0
    assert "nonsense" in p.stderr


def test_missing_input_is_a_clear_error(tmp_path):
    p = run([BIN, "-f", "GPKG", tmp_path / "x.gpkg", tmp_path / "no-such-city.gml"], check=False)
    assert p.returncode != 0
    assert "no-such-city.gml" in p.stderr
    assert not (tmp_path / "x.gpkg").exists()


def test_shapefile_output(tmp_path):
    out = tmp_path / "plans.shp"
    run([BIN, "-f", "ESRI Shapefile", out, PLATEAU_SMALL])
    ds = ogr.Open(str(out))
    lyr = ds.GetLayer(0)
    assert lyr.GetFeatureCount() > 0
    assert lyr.GetSpatialRef() is not None
    for f in lyr:
        assert f.GetGeometryRef().IsValid()


def test_kmz_models_through_both_routes(tmp_path):
    """Google's shared-textures KMZ: two COLLADA models placed at one Location in San Francisco."""
    kmz = SHARED_DATA / "kml-collada-macky-google" / "shared-textures.kmz"
    a, b = tmp_path / "cli.gpkg", tmp_path / "ogr2ogr.gpkg"
    run([BIN, "--verify", "-f", "GPKG", a, kmz, "ground_plans", "footprints"])
    run(["ogr2ogr", "-f", "GPKG", b, f"GROUNDPLAN:{kmz}", "ground_plans"])
    assert layer_rows(a, "ground_plans") == layer_rows(b, "ground_plans")
    ds = ogr.Open(str(a))
    lyr = ds.GetLayerByName("ground_plans")
    assert lyr.GetSpatialRef().GetAuthorityCode(None) == "32610"  # UTM 10N: San Francisco
    assert ds.GetLayerByName("footprints").GetFeatureCount() == 2
    minx, maxx, miny, maxy = lyr.GetExtent()
    # The anchor, lon -122.451703589982 lat 37.80564180933, is at E 548,265.92 N 4,184,392.50 in UTM 10N (cs2cs).
    assert minx < 548266 + 200 and maxx > 548266 - 200 and miny < 4184392 + 200 and maxy > 4184392 - 200

# SPDX-License-Identifier: MIT
"""test_ogrsf-style checks of the driver's layers (GDAL's test_ogrsf is not packaged in Debian): counts,
random reads, filters, extents and capabilities behave as OGR users expect."""
import pytest
from osgeo import gdal, ogr

from conftest import LORUP

gdal.UseExceptions()


@pytest.fixture(scope="module")
def ds():
    d = gdal.OpenEx(f"GROUNDPLAN:{LORUP}", gdal.OF_VECTOR)
    assert d.GetDriver().ShortName == "GroundPlan"
    return d


def test_layers_and_crs(ds):
    names = [ds.GetLayer(i).GetName() for i in range(ds.GetLayerCount())]
    assert names == ["ground_plans", "footprints", "problems", "plan_members"]
    srs = ds.GetLayerByName("ground_plans").GetSpatialRef()
    assert srs.GetAuthorityCode(None) == "25832"  # Lorup's srsName (EPSG:25832 + height) is projected: kept
    assert ds.GetLayerByName("problems").GetGeomType() == ogr.wkbNone


@pytest.mark.parametrize("name", ["ground_plans", "footprints", "problems", "plan_members"])
def test_count_iteration_and_random_read_agree(ds, name):
    lyr = ds.GetLayerByName(name)
    assert lyr.TestCapability(ogr.OLCFastFeatureCount)
    lyr.ResetReading()
    feats = [f for f in lyr]
    assert len(feats) == lyr.GetFeatureCount()
    for f in feats:
        g = lyr.GetFeature(f.GetFID())
        assert g.Equal(f)
    assert lyr.GetFeature(0) is None and lyr.GetFeature(len(feats) + 1) is None
    lyr.ResetReading()  # reading again gives the same first feature
    if feats:
        assert lyr.GetNextFeature().Equal(feats[0])


def test_extent_holds_every_geometry(ds):
    lyr = ds.GetLayerByName("ground_plans")
    minx, maxx, miny, maxy = lyr.GetExtent()
    for f in lyr:
        e = f.GetGeometryRef().GetEnvelope()
        assert minx <= e[0] and e[1] <= maxx and miny <= e[2] and e[3] <= maxy


def test_spatial_filter(ds):
    lyr = ds.GetLayerByName("ground_plans")
    minx, maxx, miny, maxy = lyr.GetExtent()
    box = (minx, miny, (minx + maxx) / 2, (miny + maxy) / 2)
    window = ogr.CreateGeometryFromWkt(
        f"POLYGON(({box[0]} {box[1]},{box[2]} {box[1]},{box[2]} {box[3]},{box[0]} {box[3]},{box[0]} {box[1]}))")
    expected = sum(1 for f in lyr if f.GetGeometryRef().Intersects(window))
    lyr.SetSpatialFilterRect(*box)
    try:
        assert not lyr.TestCapability(ogr.OLCFastFeatureCount)
        got = [f.GetFID() for f in lyr]
        assert 0 < len(got) == lyr.GetFeatureCount()
        # OGR's filter is envelope-then-geometry: it may keep no more than the envelope test and no fewer than true hits.
        assert len(got) >= expected
    finally:
        lyr.SetSpatialFilter(None)


def test_attribute_filter(ds):
    lyr = ds.GetLayerByName("ground_plans")
    expected = sum(1 for f in lyr if f["n_parts"] > 1)
    lyr.SetAttributeFilter("n_parts > 1")
    try:
        assert lyr.GetFeatureCount() == expected > 0
        assert all(f["n_parts"] > 1 for f in lyr)
    finally:
        lyr.SetAttributeFilter(None)
    assert lyr.GetFeatureCount() > expected


def test_members_table_matches_the_id_lists(ds):
    plans = {f["gp_id"]: f["building_ids"].split(",") for f in ds.GetLayerByName("ground_plans")}
    members = {}
    for f in ds.GetLayerByName("plan_members"):
        members.setdefault(f["gp_id"], []).append(f["source_id"])
    assert members == plans


def test_update_mode_gives_read_only_layers():
    # Issue 18: update access (QGIS probes it on every load) opens without an error, and nothing can be
    # written: the dataset makes no layer, its layers take no feature (test_driver_cache.py checks those).
    ds = gdal.OpenEx(f"GROUNDPLAN:{LORUP}", gdal.OF_VECTOR | gdal.OF_UPDATE)
    assert not ds.TestCapability(ogr.ODsCCreateLayer) and not ds.TestCapability(ogr.ODsCDeleteLayer)
    with pytest.raises(RuntimeError, match="not supported"):
        ds.CreateLayer("x", geom_type=ogr.wkbPolygon)
    assert ds.GetLayerCount() == 4

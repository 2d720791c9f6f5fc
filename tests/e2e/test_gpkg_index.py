# SPDX-License-Identifier: MIT
"""The GeoPackage spatial index the CLI packs itself (issue 14, driver/output/gpkg_rtree.h) is the one GDAL's
own writer makes, seen from any reader: the same schema (tables, triggers, extension row, word for word),
the same index entries (boxes rounded to float as SQLite rounds them), a tree SQLite's rtreecheck()
accepts, the same answers to window queries, and triggers that keep it right when the file is edited."""
import json
import random
import sqlite3

import pytest
from osgeo import gdal, ogr

from conftest import BERLIN, BIN, LORUP, PLATEAU, SHARED_DATA, run, thirdparty_data

INDEX = "rtree_{0}_geom"
SCHEMA = "SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY type, name"
ENTRIES = "SELECT id, minx, maxx, miny, maxy FROM {0} ORDER BY id"
LAYERS = ["ground_plans", "footprints"]

packs_index = int(gdal.VersionInfo()) < 3070000  # GDAL >= 3.7 builds its own in a background thread


def write(tmp_path, name, src, *flags):
    out = tmp_path / f"{name}.gpkg"
    stats = tmp_path / f"{name}.json"
    run([BIN, "-q", "--stats", stats, *flags, "-f", "GPKG", out, src, *LAYERS])
    return out, json.loads(stats.read_text())


def entries(db, layer):
    return list(db.execute(ENTRIES.format(INDEX.format(layer))))


@pytest.mark.skipif(not packs_index, reason="GDAL >= 3.7 builds the index itself")
@pytest.mark.parametrize("src", [PLATEAU, LORUP, pytest.param(BERLIN, marks=thirdparty_data),
                                 SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"],
                         ids=lambda p: p.name)
def test_packed_index_is_the_one_gdal_makes(tmp_path, src):
    ours, ours_stats = write(tmp_path, "ours", src)
    gdals, gdals_stats = write(tmp_path, "gdal", src, "-lco", "SPATIAL_INDEX=YES")
    assert ours_stats["timings_s"]["spatial_index"] > 0, "the CLI did not build the index itself"
    assert gdals_stats["timings_s"]["spatial_index"] == 0, "-lco SPATIAL_INDEX=YES must leave it to GDAL"
    a, b = sqlite3.connect(ours), sqlite3.connect(gdals)
    assert list(a.execute(SCHEMA)) == list(b.execute(SCHEMA))
    assert list(a.execute("SELECT * FROM gpkg_extensions ORDER BY table_name")) == \
        list(b.execute("SELECT * FROM gpkg_extensions ORDER BY table_name"))
    for layer in LAYERS:
        index = INDEX.format(layer)
        got = entries(a, layer)
        assert got == entries(b, layer)
        assert len(got) == a.execute(f"SELECT count(*) FROM {layer}").fetchone()[0] > 0
        assert a.execute(f"SELECT rtreecheck('{index}')").fetchone()[0] == "ok"
        # Window queries through the index, as a spatial filter does: the same ids from both trees.
        lo_x, hi_x, lo_y, hi_y = a.execute(f"SELECT min(minx), max(maxx), min(miny), max(maxy) FROM {index}").fetchone()
        rnd = random.Random(7)
        query = f"SELECT id FROM {index} WHERE minx <= ? AND maxx >= ? AND miny <= ? AND maxy >= ? ORDER BY id"
        for _ in range(100):
            x, y = rnd.uniform(lo_x, hi_x), rnd.uniform(lo_y, hi_y)
            w, h = rnd.uniform(0, (hi_x - lo_x) / 5), rnd.uniform(0, (hi_y - lo_y) / 5)
            args = (x + w, x, y + h, y)
            assert list(a.execute(query, args)) == list(b.execute(query, args))
    assert a.execute("PRAGMA integrity_check").fetchone()[0] == "ok"


@pytest.mark.skipif(not packs_index, reason="GDAL >= 3.7 builds the index itself")
def test_gdal_uses_the_packed_index_and_its_triggers_keep_it_right(tmp_path):
    out, _ = write(tmp_path, "ours", PLATEAU)
    ds = gdal.OpenEx(str(out), gdal.OF_VECTOR | gdal.OF_UPDATE)
    lyr = ds.GetLayerByName("ground_plans")
    assert lyr.TestCapability(ogr.OLCFastSpatialFilter)
    n = lyr.GetFeatureCount()
    ext = lyr.GetExtent()
    cx, cy = (ext[0] + ext[1]) / 2, (ext[2] + ext[3]) / 2
    lyr.SetSpatialFilterRect(cx - 50, cy - 50, cx + 50, cy + 50)
    lyr.ResetReading()
    filtered = {f.GetFID() for f in lyr}
    lyr.SetSpatialFilter(None)
    window = ogr.CreateGeometryFromWkt(f"POLYGON(({cx-50} {cy-50},{cx+50} {cy-50},{cx+50} {cy+50},{cx-50} {cy+50},"
                                       f"{cx-50} {cy-50}))")
    lyr.ResetReading()
    brute = {f.GetFID() for f in lyr if f.GetGeometryRef().Intersects(window)}
    assert brute and brute <= filtered
    # Edits through GDAL: the triggers (GDAL's SQL functions) must keep the tree valid and complete.
    lyr.ResetReading()
    f = lyr.GetNextFeature()
    lyr.DeleteFeature(f.GetFID())
    g = ogr.CreateGeometryFromWkt(f"POLYGON(({cx} {cy},{cx+1} {cy},{cx+1} {cy+1},{cx} {cy}))")
    nf = ogr.Feature(lyr.GetLayerDefn())
    nf.SetGeometry(g)
    lyr.CreateFeature(nf)
    ds = None
    db = sqlite3.connect(out)
    assert db.execute("SELECT rtreecheck('rtree_ground_plans_geom')").fetchone()[0] == "ok"
    assert db.execute("SELECT count(*) FROM rtree_ground_plans_geom").fetchone()[0] == n
    assert db.execute("SELECT count(*) FROM rtree_ground_plans_geom WHERE id = ?", (f.GetFID(),)).fetchone()[0] == 0


def test_the_users_spatial_index_choice_is_kept(tmp_path):
    out, stats = write(tmp_path, "none", LORUP, "-lco", "SPATIAL_INDEX=NO")
    assert stats["timings_s"]["spatial_index"] == 0
    db = sqlite3.connect(out)
    assert db.execute("SELECT count(*) FROM sqlite_master WHERE name LIKE 'rtree_%'").fetchone()[0] == 0

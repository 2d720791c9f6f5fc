# SPDX-License-Identifier: MIT
"""A new GeoPackage written by several writers side by side (issue 14, driver/output/gpkg_slices.h) is the file one
writer makes, seen from any reader: the same schema, rows (FID, every field, the geometry blob byte for byte),
extent, feature count and spatial index; no slice file is left beside it. Options whose effect spans features
keep one writer, and --stats says which was used and why. By default the writers start while the union goes on
(driver/output/streamed_gpkg.h); --config GROUNDPLAN_WRITE_DURING_UNION NO writes after it: both give that file."""
import json
import sqlite3

import pytest
from osgeo import gdal

from conftest import BIN, run

packs_index = int(gdal.VersionInfo()) < 3070000  # the slices are the CLI's only where it packs the index too
pytestmark = pytest.mark.skipif(not packs_index, reason="GDAL >= 3.7 writes GeoPackages its own way")

SCHEMA = "SELECT type, name, tbl_name, sql FROM sqlite_master ORDER BY type, name"
CONTENTS = "SELECT table_name, data_type, identifier, min_x, min_y, max_x, max_y, srs_id FROM gpkg_contents ORDER BY 1"


AFTER_UNION = ["--config", "GROUNDPLAN_WRITE_DURING_UNION", "NO"]


def write(folder, name, src, threads, *args):
    out, stats = folder / f"{name}.gpkg", folder / f"{name}.json"
    run([BIN, "-q", "--threads", str(threads), "--stats", stats, "-f", "GPKG", out, src, *args])
    return out, json.loads(stats.read_text())


def check_writers(stats, mode, writers):
    """After the union: `writers` slices, as gpkg_writers says. During it: two or more writers (their number is
    set from a guess of the plans' number), every slice of them written, the first ones before the union ended."""
    w = stats["writer"]
    if mode == "after":
        assert w["writers"] == writers and "during_union" not in w, w
    else:
        assert w["during_union"] is True and 2 <= w["writers"] <= writers, w
        assert w["slices"] >= w["writers"] and w["slices_started_during_union"] >= 1, w


def same_file_content(a_path, b_path, tables):
    a, b = sqlite3.connect(a_path), sqlite3.connect(b_path)
    assert list(a.execute(SCHEMA)) == list(b.execute(SCHEMA))
    assert list(a.execute(CONTENTS)) == list(b.execute(CONTENTS))
    assert list(a.execute("SELECT * FROM gpkg_ogr_contents ORDER BY 1")) == \
        list(b.execute("SELECT * FROM gpkg_ogr_contents ORDER BY 1"))
    for t in tables:
        rows = list(a.execute(f'SELECT * FROM "{t}" ORDER BY fid'))
        assert rows == list(b.execute(f'SELECT * FROM "{t}" ORDER BY fid')), t
        assert [r[0] for r in rows] == list(range(1, len(rows) + 1)), f"{t}: FIDs are not 1..N in order"
        count = a.execute("SELECT feature_count FROM gpkg_ogr_contents WHERE table_name = ?", (t,)).fetchone()[0]
        assert count == len(rows)
    assert a.execute("PRAGMA integrity_check").fetchone()[0] == "ok"


@pytest.mark.parametrize("mode", ["during", "after"])
def test_slices_give_the_one_writer_file(tmp_path, parts, mode):
    one, one_stats = write(tmp_path, "one", parts, 1)
    many, many_stats = write(tmp_path, "many", parts, 4, *(AFTER_UNION if mode == "after" else []))
    assert one_stats["writer"] == {"writers": 1, "why_one": "one thread"}
    check_writers(many_stats, mode, 4)
    plans = many_stats["counts"]["ground_plans"]
    assert plans > 4 * 8192 and plans == one_stats["counts"]["ground_plans"]
    same_file_content(many, one, ["ground_plans"])
    db = sqlite3.connect(many)
    assert db.execute("SELECT count(*) FROM ground_plans").fetchone()[0] == plans
    assert db.execute("SELECT count(*) FROM rtree_ground_plans_geom").fetchone()[0] == plans
    assert db.execute("SELECT rtreecheck('rtree_ground_plans_geom')").fetchone()[0] == "ok"
    # The triggers are back: a row added by a GDAL user is counted and indexed.
    ds = gdal.OpenEx(str(many), gdal.OF_VECTOR | gdal.OF_UPDATE)
    lyr = ds.GetLayer("ground_plans")
    from osgeo import ogr
    f = ogr.Feature(lyr.GetLayerDefn())
    f.SetGeometry(ogr.CreateGeometryFromWkt("POLYGON ((1 1, 2 1, 2 2, 1 1))"))
    assert lyr.CreateFeature(f) == 0
    ds = None
    db = sqlite3.connect(many)
    assert db.execute("SELECT feature_count FROM gpkg_ogr_contents WHERE table_name = 'ground_plans'").fetchone()[0] \
        == plans + 1
    assert db.execute("SELECT count(*) FROM rtree_ground_plans_geom").fetchone()[0] == plans + 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["many.gpkg", "many.json", "one.gpkg", "one.json"], \
        "a slice file was left behind"


@pytest.mark.parametrize("mode", ["during", "after"])
def test_other_layers_and_a_new_name(tmp_path, parts, mode):
    """Slice 0 carries the other layers: written during the union, it waits for the union's end (problems)."""
    extra = AFTER_UNION if mode == "after" else []
    layers = ["ground_plans", "problems", "plan_members"]
    one, _ = write(tmp_path, "one", parts, 1, *layers)
    many, stats = write(tmp_path, "many", parts, 4, *extra, *layers)
    check_writers(stats, mode, 4)
    assert stats["counts"]["problems"] >= 5
    same_file_content(many, one, layers)
    one, _ = write(tmp_path, "one_nln", parts, 1, "-nln", "blocks")
    many, stats = write(tmp_path, "many_nln", parts, 3, *extra, "-nln", "blocks")
    check_writers(stats, mode, 3)
    same_file_content(many, one, ["blocks"])


@pytest.mark.parametrize("mode", ["during", "after"])
def test_a_failed_write_leaves_nothing(tmp_path, parts, mode):
    """A slice GDAL cannot write (here every one: a geometry column named as the FID column) fails the run, and
    neither the destination nor a slice is left."""
    out = tmp_path / "out" / "bad.gpkg"
    out.parent.mkdir()
    r = run([BIN, "-q", "--threads", "4", *(AFTER_UNION if mode == "after" else []), "-f", "GPKG",
             "-lco", "GEOMETRY_NAME=fid", out, parts], check=False)
    assert r.returncode == 1, r.stderr
    assert "writing slice" in r.stderr and "could not write" in r.stderr, r.stderr
    assert list(out.parent.iterdir()) == [], "something was left behind"


@pytest.mark.parametrize("option", [["-where", "n_parts > 1"], ["-limit", "100"], ["-preserve_fid"]],
                         ids=lambda o: o[0])
def test_options_across_features_keep_one_writer(tmp_path, parts, option):
    many, stats = write(tmp_path, "many", parts, 4, *option)
    assert stats["writer"] == {"writers": 1, "why_one": f"ogr2ogr option {option[0]}"}
    rows = sqlite3.connect(many).execute("SELECT count(*) FROM ground_plans").fetchone()[0]
    if option[0] == "-limit":  # ogr2ogr stops reading early: the CLI once freed the layers in the wrong order
        assert rows == 100
    elif option[0] == "-where":
        assert 0 < rows < stats["counts"]["ground_plans"]
    else:
        assert rows == stats["counts"]["ground_plans"]


def test_tiled_run_slices_too(tmp_path, parts):
    """The tiled run (--tiles on, and so rank 0 over MPI) reads its plans back from the spill: writers side by side
    read it at once, and the file is the one-writer file."""
    data = json.loads(parts.read_text())
    tiles = tmp_path / "tiles"
    tiles.mkdir()
    n = len(data["features"])
    for k in range(3):  # the parts in three files, cut inside rows of the grid: plans cross the cuts
        part = dict(data, features=data["features"][k * n // 3:(k + 1) * n // 3])
        (tiles / f"t{k}.geojson").write_text(json.dumps(part))
    one, one_stats = write(tmp_path, "one", tiles, 1, "--tiles", "on")
    many, many_stats = write(tmp_path, "many", tiles, 4, "--tiles", "on")
    assert many_stats["writer"]["writers"] == 4 and one_stats["writer"]["writers"] == 1
    assert many_stats["tiles"]["seam_plans"] > 0
    same_file_content(many, one, ["ground_plans"])

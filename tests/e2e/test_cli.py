# SPDX-License-Identifier: MIT
"""The CLI as a shell user meets it: ogr2ogr options, its own flags, exit codes and messages."""
import json

from osgeo import ogr

from conftest import BIN, PLATEAU_SMALL, SHARED_DATA, TUM, run

NIEDERSACHSEN_TILES = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"


def test_help_and_version():
    p = run([BIN, "--help"])
    for flag in ("--resolution", "--device", "--footprints", "--lod", "--verify", "--stats", "--preview"):
        assert flag in p.stdout
    assert run([BIN, "--version"]).stdout.startswith("groundplan ")


def test_stats_json(tmp_path):
    stats = tmp_path / "s.json"
    run([BIN, "--stats", stats, "-f", "GPKG", tmp_path / "o.gpkg", PLATEAU_SMALL])
    j = json.loads(stats.read_text())
    assert set(j["counts"]) >= {"buildings", "footprints", "blocks", "ground_plans", "holes", "problems"}
    assert set(j["timings_s"]) >= {"read", "footprints", "blocks", "union", "write"}
    assert j["raster_backend"] == "cpu"  # no GPU here (and none in CI)
    assert 1 <= j["counts"]["blocks"] <= j["counts"]["ground_plans"]  # a block gives one plan or more
    assert j["counts"]["buildings"] == 25 and j["counts"]["ground_plans"] == 23


def test_ogr2ogr_options_pass_through(tmp_path):
    out = tmp_path / "o.gpkg"
    run([BIN, "-f", "GPKG", "-nln", "plans", "-t_srs", "EPSG:4326", "-where", "n_parts > 1", out, PLATEAU_SMALL])
    ds = ogr.Open(str(out))  # keep the dataset alive while its layer is used
    lyr = ds.GetLayerByName("plans")
    assert lyr is not None
    assert lyr.GetSpatialRef().GetAuthorityCode(None) == "4326"
    assert lyr.GetFeatureCount() >= 1
    assert all(f["n_parts"] > 1 for f in lyr)
    minx, maxx, miny, maxy = lyr.GetExtent()
    assert 139 < minx < 140 and 35 < miny < 36  # Tokyo, lon/lat in GIS order


def test_progress_is_shown(tmp_path):
    p = run([BIN, "-progress", "-f", "GPKG", tmp_path / "o.gpkg", TUM])
    assert "100 - done" in p.stdout


def test_overwrite_and_append(tmp_path):
    out = tmp_path / "o.gpkg"
    run([BIN, "-f", "GPKG", out, TUM])
    run([BIN, "-f", "GPKG", out, TUM])  # as ogr2ogr: a new GPKG replaces the old one
    run([BIN, "-overwrite", "-f", "GPKG", out, TUM])
    run([BIN, "-append", "-f", "GPKG", out, TUM])
    ds = ogr.Open(str(out))
    assert ds.GetLayerByName("ground_plans").GetFeatureCount() == 2


def test_dbf_keeps_long_member_lists_beside(tmp_path):
    out = tmp_path / "plans.shp"
    p = run([BIN, "-f", "ESRI Shapefile", out, NIEDERSACHSEN_TILES])
    assert "DBF field" in p.stderr and "plans_members.dbf" in p.stderr
    plans_ds = ogr.Open(str(out))
    plans = plans_ds.GetLayer(0)
    assert plans.GetLayerDefn().GetFieldIndex("bldg_ids") >= 0
    cut = [f for f in plans if f["bldg_ids"].endswith(")") and "...(+" in f["bldg_ids"]]
    assert cut and all(len(f["bldg_ids"]) <= 254 for f in cut)
    members_ds = ogr.Open(str(tmp_path / "plans_members.dbf"))
    members = members_ds.GetLayer(0)
    per_plan = {}
    for f in members:
        per_plan[f["gp_id"]] = per_plan.get(f["gp_id"], 0) + 1
    plans.ResetReading()
    for f in plans:
        assert per_plan[f["gp_id"]] == f["n_parts"]


def test_preview_png(tmp_path):
    png = tmp_path / "p.png"
    run([BIN, "--preview", png, "-f", "GPKG", tmp_path / "o.gpkg", PLATEAU_SMALL])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_unwritable_output_fails_with_the_name(tmp_path):
    p = run([BIN, "-f", "GPKG", "/nonexistent-dir/out.gpkg", TUM], check=False)
    assert p.returncode == 1
    assert "/nonexistent-dir/out.gpkg" in p.stderr


def test_unknown_crs_fails(tmp_path):
    p = run([BIN, "-t_srs", "EPSG:999999", "-f", "GPKG", tmp_path / "o.gpkg", TUM], check=False)
    assert p.returncode != 0
    assert "999999" in p.stderr


def test_bad_flag_value_fails():
    p = run([BIN, "--device", "quantum", "-f", "GPKG", "/tmp/x.gpkg", TUM], check=False)
    assert p.returncode == 1
    assert "quantum" in p.stderr


def test_device_cuda_runs_or_says_what_is_missing(tmp_path):
    """--device cuda: the plans from the GPU where the CUDA module loads and a device answers; elsewhere exit status 1
    with a line saying which is missing (the module, or a driver/device), never a crash and never a quiet CPU run."""
    stats = tmp_path / "s.json"
    p = run([BIN, "--device", "cuda", "--stats", stats, "-f", "GPKG", tmp_path / "c.gpkg", TUM], check=False)
    if p.returncode == 0:
        assert json.loads(stats.read_text())["raster_backend"] == "cuda"
        return
    assert p.returncode == 1, p.stderr
    assert ("libgroundplan_cuda.so.0 could not be loaded" in p.stderr or "no CUDA device answers" in p.stderr), p.stderr
    assert "use --device cpu" in p.stderr
    assert not stats.exists()


def test_garbage_input_fails_with_the_name(tmp_path):
    bad = tmp_path / "garbage.gml"
    bad.write_bytes(b"\x00\x01 this is not XML <<<")
    p = run([BIN, "-f", "GPKG", tmp_path / "o.gpkg", bad], check=False)
    assert p.returncode == 1
    assert "garbage.gml" in p.stderr

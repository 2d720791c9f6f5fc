# SPDX-License-Identifier: MIT
"""Level of detail (issue 9) as users meet it: CLI flags, the preset, driver open options (the same
plans through both routes), what --stats and the problems layer say, and refusals of bad values."""
import json

from osgeo import ogr

from conftest import BERLIN, BIN, LORUP, TUM, layer_rows, run, thirdparty_data

LOD_FLAGS = ("--snap", "--close-gaps", "--min-hole-area", "--min-area", "--simplify", "--resolution-mode", "--preset")


def _stats(tmp_path, args, src):
    stats = tmp_path / "s.json"
    out = tmp_path / "o.gpkg"
    p = run([BIN, "-overwrite", "--stats", stats, *args, "-f", "GPKG", out, src])
    return json.loads(stats.read_text()), p, out


def _all_valid_and_disjoint(path):
    ds = ogr.Open(str(path))
    geoms = [f.GetGeometryRef().Clone() for f in ds.GetLayerByName("ground_plans")]
    assert geoms
    assert all(g.IsValid() for g in geoms)
    for i, a in enumerate(geoms):
        for b in geoms[i + 1:]:
            if a.Intersects(b):
                assert a.Intersection(b).GetArea() == 0
    return geoms


def test_help_lists_every_level_of_detail_flag():
    out = run([BIN, "--help"]).stdout
    for flag in LOD_FLAGS:
        assert flag in out, flag


def test_open_options_are_documented():
    doc = run(["ogrinfo", "--format", "GroundPlan"]).stdout
    for option in ("SNAP", "CLOSE_GAPS", "MIN_HOLE_AREA", "MIN_AREA", "SIMPLIFY", "RESOLUTION_MODE", "PRESET"):
        assert option in doc, option


@thirdparty_data
def test_default_is_exact_and_stats_say_nothing_changed(tmp_path):
    j, _, _ = _stats(tmp_path, [], BERLIN)
    assert "level_of_detail" not in j
    assert j["counts"]["holes"] == 39  # the exact union keeps every sliver (sample_data/README.md)


@thirdparty_data
def test_snap_removes_slivers_and_verify_checks_validity(tmp_path):
    j, p, out = _stats(tmp_path, ["--snap", "0.001", "--verify"], BERLIN)
    lod = j["level_of_detail"]
    assert lod["params"]["snap_m"] == 0.001
    assert lod["snap"]["vertices_moved"] + lod["snap"]["vertices_inserted"] > 0
    assert j["counts"]["holes"] < 39
    assert "verify (level of detail on): VALID" in p.stdout
    assert j["verify"]["valid_and_disjoint"] is True and j["verify"]["level_of_detail"] is True
    assert "level of detail" in p.stdout
    _all_valid_and_disjoint(out)


def test_close_gaps_joins_plans_and_keeps_every_building(tmp_path):
    exact, _, _ = _stats(tmp_path, [], LORUP)
    j, _, out = _stats(tmp_path, ["--close-gaps", "0.5"], LORUP)
    assert j["counts"]["ground_plans"] < exact["counts"]["ground_plans"]
    assert j["level_of_detail"]["close_gaps"]["plans_after"] == j["counts"]["ground_plans"]
    assert j["level_of_detail"]["close_gaps"]["area_added_m2"] > 0
    geoms = _all_valid_and_disjoint(out)
    # every building is still listed in some plan
    ids = set()
    for f, _ in layer_rows(out, "ground_plans"):
        ids.update(f["building_ids"].split(","))
    assert len(ids) == exact["counts"]["footprints"]
    assert len(geoms) == j["counts"]["ground_plans"]


def test_min_area_and_min_hole_area_are_reported_in_problems(tmp_path):
    out = tmp_path / "o.gpkg"
    stats = tmp_path / "s.json"
    run([BIN, "--stats", stats, "--min-hole-area", "1", "--min-area", "50", "-f", "GPKG", out, LORUP,
         "ground_plans", "problems"])
    j = json.loads(stats.read_text())
    lod = j["level_of_detail"]
    assert lod["min_hole_area"]["holes_filled"] == 6  # the six slivers of the Lorup tile (all < 1 m2)
    assert lod["min_area"]["plans_dropped"] >= 1
    codes = [f["code"] for f, _ in layer_rows(out, "problems")]
    assert codes.count("HOLE_BELOW_MIN_AREA") == 6
    assert codes.count("PLAN_BELOW_MIN_AREA") >= lod["min_area"]["plans_dropped"]
    areas = [f["area_m2"] for f, _ in layer_rows(out, "ground_plans")]
    assert min(areas) >= 50


def test_preset_cfd_and_explicit_flags_override_it(tmp_path):
    j, _, out = _stats(tmp_path, ["--preset", "cfd"], LORUP)
    params = j["level_of_detail"]["params"]
    assert params == {"snap_m": 0.01, "close_gaps_m": 0.5, "simplify_m": 0.1, "min_hole_area_m2": 1.0,
                      "min_area_m2": 1.0, "resolution_mode": "exact"}
    _all_valid_and_disjoint(out)
    j2, _, _ = _stats(tmp_path, ["--preset", "cfd", "--close-gaps", "0"], LORUP)
    assert j2["level_of_detail"]["params"]["close_gaps_m"] == 0
    assert j2["level_of_detail"]["params"]["snap_m"] == 0.01


@thirdparty_data
def test_raster_mode_fills_holes_smaller_than_a_pixel(tmp_path):
    j, _, _ = _stats(tmp_path, ["--resolution", "1", "--resolution-mode", "raster"], BERLIN)
    raster = j["level_of_detail"]["raster"]
    assert raster["pixel_m"] == 1
    assert raster["holes_filled"] > 0
    assert j["counts"]["holes"] == 39 - raster["holes_filled"]


def test_cli_and_driver_give_the_same_plans_with_open_options(tmp_path):
    a, b = tmp_path / "cli.gpkg", tmp_path / "drv.gpkg"
    run([BIN, "--snap", "0.01", "--close-gaps", "0.2", "--simplify", "0.05", "-f", "GPKG", a, LORUP])
    run(["ogr2ogr", "-f", "GPKG", "-oo", "SNAP=0.01", "-oo", "CLOSE_GAPS=0.2", "-oo", "SIMPLIFY=0.05", b,
         f"GROUNDPLAN:{LORUP}", "ground_plans"])
    rows_a, rows_b = layer_rows(a, "ground_plans"), layer_rows(b, "ground_plans")
    assert rows_a == rows_b
    exact = tmp_path / "exact.gpkg"
    run([BIN, "-f", "GPKG", exact, LORUP])
    assert rows_a != layer_rows(exact, "ground_plans")  # the options did act


def test_bad_values_are_refused_with_their_name(tmp_path):
    p = run([BIN, "--snap", "-1", "-f", "GPKG", tmp_path / "o.gpkg", TUM], check=False)
    assert p.returncode != 0 and "--snap" in p.stderr + p.stdout
    p = run([BIN, "--preset", "wind", "-f", "GPKG", tmp_path / "o.gpkg", TUM], check=False)
    assert p.returncode != 0 and "wind" in p.stderr
    p = run(["ogrinfo", "-so", "-oo", "CLOSE_GAPS=abc", f"GROUNDPLAN:{TUM}"], check=False)
    assert p.returncode != 0 and "CLOSE_GAPS" in p.stderr + p.stdout


def test_ogr2ogr_single_dash_simplify_still_reaches_gdal(tmp_path):
    j, _, out = _stats(tmp_path, ["-simplify", "0.5"], TUM)
    assert "level_of_detail" not in j  # not ours: GDAL's own -simplify
    assert ogr.Open(str(out)).GetLayerByName("ground_plans").GetFeatureCount() == 1

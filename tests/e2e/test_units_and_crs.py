# SPDX-License-Identifier: MIT
"""Heights in metres whatever the source's units, and a source without CRS written as an undefined Cartesian SRS
(never as degrees)."""
import json
import sqlite3

import pytest
from osgeo import gdal, ogr

from conftest import BIN, layer_rows, run, write_citygml

FT_US = 1200.0 / 3937.0


@pytest.mark.parametrize("srs", ["EPSG:2263", "EPSG:2263+6360", "urn:ogc:def:crs,crs:EPSG::2263,crs:EPSG::6360"])
def test_us_feet_heights_are_written_in_metres(tmp_path, srs):
    # A 118.41 m tower in New York State Plane (US survey feet): written as 388.49 ft, read as metres.
    gml = write_citygml(tmp_path / "ny.gml", [("TOWER", [(988000.0, 210000.0, 100.0, 80.0, 10.0, 388.49)], [])],
                        srs_name=srs)
    out = tmp_path / "ny.gpkg"
    run([BIN, "-f", "GPKG", out, gml, "ground_plans", "footprints", "problems"])
    [(plan, _)] = layer_rows(out, "ground_plans")
    assert plan["max_z"] == pytest.approx(388.49 * FT_US, abs=1e-6)
    assert plan["min_z"] == pytest.approx(10.0 * FT_US, abs=1e-6)
    assert plan["area_m2"] == pytest.approx(100 * 80 * FT_US ** 2, rel=1e-3)  # x, y in metres as before
    [(fp, _)] = layer_rows(out, "footprints")
    assert fp["max_z"] == pytest.approx(388.49 * FT_US, abs=1e-6)
    notes = [p["reason"] for p, _ in layer_rows(out, "problems") if p["code"] == "NOTE"]
    assert any("converted to metres" in n for n in notes), notes
    # The driver gives the same heights.
    ds = gdal.OpenEx(f"GROUNDPLAN:{gml}", gdal.OF_VECTOR)
    f = ds.GetLayerByName("ground_plans").GetNextFeature()
    assert f["max_z"] == pytest.approx(388.49 * FT_US, abs=1e-6)


def test_metre_vertical_datum_under_feet_horizontal_keeps_metres(tmp_path):
    # NAVD88 height in metres (EPSG:5703) under a horizontal CRS in feet: the vertical CRS decides.
    gml = write_citygml(tmp_path / "m.gml", [("TOWER", [(988000.0, 210000.0, 100.0, 80.0, 10.0, 118.41)], [])],
                        srs_name="EPSG:2263+5703")
    out = tmp_path / "m.gpkg"
    run([BIN, "-f", "GPKG", out, gml])
    [(plan, _)] = layer_rows(out, "ground_plans")
    assert plan["max_z"] == pytest.approx(118.41, abs=1e-9)


def test_no_crs_is_an_undefined_cartesian_srs_never_degrees(tmp_path):
    gml = write_citygml(tmp_path / "local.gml", [("B1", [(1000.0, 2000.0, 10.0, 8.0, 0.0, 9.0)], [])])
    out = tmp_path / "local.gpkg"
    run([BIN, "-f", "GPKG", out, gml, "ground_plans", "footprints", "problems"])
    with sqlite3.connect(out) as db:
        rows = dict(db.execute("SELECT table_name, srs_id FROM gpkg_geometry_columns").fetchall())
    assert rows == {"ground_plans": -1, "footprints": -1}
    ds = ogr.Open(str(out))
    srs = ds.GetLayerByName("ground_plans").GetSpatialRef()
    assert srs is None or not srs.IsGeographic()
    notes = [p["reason"] for p, _ in layer_rows(out, "problems") if p["code"] == "NOTE"]
    assert any("-a_srs" in n and "no srsName" in n for n in notes), notes
    # The driver's layers say the same to any writer (here GDAL's own GeoPackage writer).
    drv = tmp_path / "drv.gpkg"
    src = gdal.OpenEx(f"GROUNDPLAN:{gml}", gdal.OF_VECTOR)
    assert not src.GetLayerByName("ground_plans").GetSpatialRef().IsGeographic()
    gdal.VectorTranslate(str(drv), src, format="GPKG", layers=["ground_plans"])
    src = None
    with sqlite3.connect(drv) as db:
        assert db.execute("SELECT srs_id FROM gpkg_geometry_columns").fetchall() == [(-1,)]


def _mixed_folder(tmp_path, crs_first):
    """A folder of a file in EPSG:25832 and one without srsName; `crs_first` decides which sorts first."""
    folder = tmp_path / ("crs_first" if crs_first else "crs_last")
    folder.mkdir()
    with_crs, without = ("a.gml", "b.gml") if crs_first else ("b.gml", "a.gml")
    write_citygml(folder / with_crs, [("GEO_1", [(500000.0, 5700000.0, 10.0, 10.0, 0.0, 5.0)], []),
                                      ("GEO_2", [(500020.0, 5700000.0, 10.0, 10.0, 0.0, 5.0)], [])],
                  srs_name="EPSG:25832")
    write_citygml(folder / without, [("LOCAL_1", [(10.0, 10.0, 5.0, 5.0, 0.0, 3.0)], []),
                                     ("LOCAL_2", [(30.0, 10.0, 5.0, 5.0, 0.0, 3.0)], [])])
    return folder, folder / without


@pytest.mark.parametrize("crs_first", [True, False], ids=["georeferenced-first", "georeferenced-last"])
def test_a_file_without_crs_among_georeferenced_ones_is_a_problem_whatever_the_order(tmp_path, crs_first):
    folder, without = _mixed_folder(tmp_path, crs_first)
    out, stats = tmp_path / "out.gpkg", tmp_path / "stats.json"
    p = run([BIN, "--stats", stats, "-f", "GPKG", out, folder, "ground_plans", "footprints", "problems"])
    assert "target CRS" not in p.stderr and "was asked for" not in p.stderr, p.stderr
    assert sorted(f["source_id"] for f, _ in layer_rows(out, "footprints")) == ["GEO_1", "GEO_2"]
    ds = ogr.Open(str(out))
    srs = ds.GetLayerByName("ground_plans").GetSpatialRef()
    assert srs.GetAuthorityCode(None) == "25832"
    problems = [f for f, _ in layer_rows(out, "problems")]
    no_crs = sorted((pr["source_id"], pr["file"]) for pr in problems if pr["code"] == "NO_CRS")
    assert no_crs == [("", str(without)), ("LOCAL_1", str(without)), ("LOCAL_2", str(without))]
    [file_problem] = [pr["reason"] for pr in problems if pr["code"] == "NO_CRS" and not pr["source_id"]]
    assert str(without) in file_problem and "no srsName" in file_problem and "-s_srs" in file_problem
    assert "EPSG:25832" in file_problem
    # No note tells the output is unreferenced: it is georeferenced.
    assert not any("undefined Cartesian" in pr["reason"] for pr in problems), problems
    counts = json.loads(stats.read_text())["counts"]
    assert (counts["buildings"], counts["footprints"], counts["dropped"]) == (4, 2, 2)


def test_the_driver_sets_aside_a_file_without_crs_too(tmp_path):
    folder, without = _mixed_folder(tmp_path, crs_first=False)
    ds = gdal.OpenEx(f"GROUNDPLAN:{folder}", gdal.OF_VECTOR)
    assert sorted(f["source_id"] for f in ds.GetLayerByName("footprints")) == ["GEO_1", "GEO_2"]
    assert {f["source_id"] for f in ds.GetLayerByName("problems") if f["code"] == "NO_CRS"} == {"", "LOCAL_1", "LOCAL_2"}


@pytest.mark.parametrize("where", ["LandUse", "LandUse-after", None],
                         ids=["landuse-envelope", "landuse-after-the-buildings", "citymodel-envelope"])
def test_srs_name_on_any_envelope_is_found(tmp_path, where):
    gml = write_citygml(tmp_path / "e.gml", [("B1", [(500000.0, 5700000.0, 10.0, 10.0, 0.0, 5.0)], [])],
                        srs_name="EPSG:25832", envelope_on=where)
    out = tmp_path / "e.gpkg"
    p = run([BIN, "-f", "GPKG", out, gml, "ground_plans", "problems"])
    assert "no srsName" not in p.stderr, p.stderr
    ds = ogr.Open(str(out))
    srs = ds.GetLayerByName("ground_plans").GetSpatialRef()
    assert srs is not None and srs.GetAuthorityCode(None) == "25832"
    problems = [f for f, _ in layer_rows(out, "problems")]
    if where == "LandUse-after":  # said, not silent: the CRS comes from after the first building
        assert [p["code"] for p in problems] == ["NOTE"] and "only after the file's first building" in problems[0]["reason"]
    else:
        assert not problems


def test_problems_and_notes_are_counted_alike_everywhere(tmp_path):
    # 25 files without srsName: a note each (no CRS), and one building each without geometry (a problem).
    folder = tmp_path / "local"
    folder.mkdir()
    for i in range(25):
        write_citygml(folder / f"t{i:02}.gml", [(f"B{i}", [(100.0 * i, 0.0, 10.0, 10.0, 0.0, 5.0)], []),
                                                (f"EMPTY{i}", [], [])])
    stats = tmp_path / "s.json"
    p = run([BIN, "--stats", stats, "-f", "GPKG", tmp_path / "o.gpkg", folder])
    import re
    summary = re.search(r"; (\d+) problems, (\d+) notes\n", p.stdout)
    assert summary, p.stdout
    problems, notes = int(summary.group(1)), int(summary.group(2))
    assert (problems, notes) == (25, 25)
    counts = json.loads(stats.read_text())["counts"]
    assert (counts["problems"], counts["notes"]) == (problems, notes)
    shown = [l for l in p.stderr.splitlines() if l.startswith("groundplan: ") and "..." not in l]
    more = re.search(r"\.\.\. and (\d+) more problems and (\d+) more notes: write the 'problems' layer", p.stderr)
    assert more, p.stderr
    shown_notes = sum(1 for l in shown if ": note: " in l)
    assert shown_notes + int(more.group(2)) == notes
    assert len(shown) - shown_notes + int(more.group(1)) == problems

# SPDX-License-Identifier: MIT
"""3D Tiles through the real CLI and the GDAL driver (the C++ reader tests compare the plans with the source
CityGML): docs/3d_tiles.md's commands run as written, GROUNDPLAN:tileset.json and a folder open in OGR, the
feature ids name the buildings."""

import json
import shutil

from osgeo import gdal

from conftest import BIN, SOURCE_DIR, run

TILES = SOURCE_DIR / "tests" / "data" / "3dtiles"


def test_docs_commands_and_driver(tmp_path):
    out = tmp_path / "plans.gpkg"
    for args in (["-f", "GPKG", out, TILES / "b3dm" / "tileset.json"],
                 ["-t_srs", "EPSG:25832", "-f", "GPKG", out, TILES / "b3dm"],
                 ["--config", "GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", "600", "-f", "GPKG", out,
                  TILES / "levels" / "replace.json"]):
        out.unlink(missing_ok=True)
        p = run([BIN, *args])
        assert "read 80 buildings" in p.stdout + p.stderr, p.stdout + p.stderr
    for name in ("GROUNDPLAN:" + str(TILES / "glb" / "tileset.json"), "GROUNDPLAN:" + str(TILES / "draco")):
        ds = gdal.OpenEx(name, gdal.OF_VECTOR)
        assert ds is not None, name
        footprints = ds.GetLayerByName("footprints")
        ids = {f.GetField("source_id") for f in footprints}
        assert len(ids) == 80 and all(i.startswith("DENILD") for i in ids), sorted(ids)[:5]


def test_folder_with_a_tileset_reads_the_city_files_beside_it(tmp_path):
    # The tiles are read through tileset.json (never again on their own); a city file of another format beside it
    # is an input of its own, not left out.
    folder = tmp_path / "tiles"
    shutil.copytree(TILES / "b3dm", folder)
    shutil.copy(SOURCE_DIR / "sample_data" / "niedersachsen-lorup" / "LoD1_24065862_2_2021-01-25.gml", folder / "extra.gml")
    stats = tmp_path / "s.json"
    p = run([BIN, "-t_srs", "EPSG:25832", "--stats", stats, "-f", "GPKG", tmp_path / "o.gpkg", folder])
    said = p.stdout + p.stderr
    s = json.loads(stats.read_text())
    counts = s["counts"]
    assert s["reading"]["files"] == 2, said
    assert counts["footprints"] > 80, (counts, said)

def test_quantized_glb_keeps_the_lossless_copys_ground(tmp_path):
    # The same 80 buildings with positions quantized to 16 bits (steps of at most 3.1 cm) and lossless: the
    # plans' areas agree within a band of half a step in 3D (2.7 cm) along the lossless plans' boundaries.
    areas, perimeters = {}, {}
    for name in ("quantized", "nodes"):
        out = tmp_path / f"{name}.gpkg"
        p = run([BIN, "-f", "GPKG", out, TILES / "meshopt" / f"{name}.json"])
        assert " 0 problems" in p.stdout + p.stderr, p.stdout + p.stderr
        ds = gdal.OpenEx(str(out), gdal.OF_VECTOR)
        plans = [f.GetGeometryRef().Clone() for f in ds.GetLayerByName("ground_plans")]
        areas[name] = sum(g.GetArea() for g in plans)
        perimeters[name] = sum(g.Boundary().Length() for g in plans)
    assert abs(areas["quantized"] - areas["nodes"]) <= perimeters["nodes"] * 0.5 * 0.031 * 3 ** 0.5, areas

# SPDX-License-Identifier: MIT
"""Plans name the Buildings, not only their parts: where the geometry sits on BuildingParts (CityGML
consistsOfBuildingPart, CityJSON "parents"), every plan member carries its Building's id beside its own
(plan_members.building_id, footprints.building_id) and every plan lists its Buildings (ground_plans.buildings),
by every route: the CLI's writers, the tiled run, the driver, the Python module."""
import csv
import json
import os
import sys

import pytest
from osgeo import gdal, ogr

from conftest import BIN, SHARED_DATA, layer_rows, run, write_citygml

BUILD_DIR = os.environ.get("GROUNDPLAN_BUILD_DIR", "")

# Two Buildings whose parts touch (one plan of four parts, two Buildings), a Building with its own solid and
# no parts, and a lone Building of two parts far away.
CITY = [
    ("HOUSE_A", [], [("A_part1", [(500000.0, 5700000.0, 10.0, 10.0, 0.0, 6.0)]),
                     ("A_part2", [(500010.0, 5700000.0, 5.0, 10.0, 0.0, 9.0)])]),
    ("HOUSE_B", [], [("B_part1", [(500015.0, 5700000.0, 8.0, 10.0, 0.0, 7.0)]),
                     ("B_part2", [(500023.0, 5700000.0, 8.0, 10.0, 0.0, 4.0)])]),
    ("SOLO", [(500100.0, 5700000.0, 10.0, 10.0, 0.0, 5.0)], []),
    ("HOUSE_C", [], [("C_part1", [(500200.0, 5700000.0, 10.0, 10.0, 0.0, 3.0)]),
                     ("C_part2", [(500205.0, 5700005.0, 10.0, 10.0, 0.0, 8.0)])]),
]
EXPECTED_MEMBERS = {"A_part1": "HOUSE_A", "A_part2": "HOUSE_A", "B_part1": "HOUSE_B", "B_part2": "HOUSE_B",
                    "SOLO": "SOLO", "C_part1": "HOUSE_C", "C_part2": "HOUSE_C"}
EXPECTED_PLANS = {"A_part1,A_part2,B_part1,B_part2": "HOUSE_A,HOUSE_B", "SOLO": "SOLO",
                  "C_part1,C_part2": "HOUSE_C"}


@pytest.fixture(scope="module")
def city_gml(tmp_path_factory):
    return write_citygml(tmp_path_factory.mktemp("identity") / "parts.gml", CITY, srs_name="EPSG:25832")


@pytest.fixture(scope="module")
def city_json(tmp_path_factory):
    """The same city as CityJSON 1.1 (parts with "parents", Buildings with "children")."""
    vertices, objects = [], {}

    def solid(boxes):
        shells = []
        for x, y, w, d, z0, z1 in boxes:
            base = len(vertices)
            for zz in (z0, z1):
                for px, py in ((x, y), (x + w, y), (x + w, y + d), (x, y + d)):
                    vertices.append([round((px - 500000) * 1000), round((py - 5700000) * 1000), round(zz * 1000)])
            b = [base + i for i in range(4)]
            t = [base + 4 + i for i in range(4)]
            faces = [[[b[0], b[3], b[2], b[1]]], [[t[0], t[1], t[2], t[3]]]]
            for i in range(4):
                j = (i + 1) % 4
                faces.append([[b[i], b[j], t[j], t[i]]])
            shells.append(faces)
        return [{"type": "Solid", "lod": "1", "boundaries": [shells[0]]}] + \
               [{"type": "Solid", "lod": "1", "boundaries": [s]} for s in shells[1:]]

    for bid, boxes, parts in CITY:
        obj = {"type": "Building"}
        if boxes:
            obj["geometry"] = solid(boxes)
        if parts:
            obj["children"] = [pid for pid, _ in parts]
        objects[bid] = obj
        for pid, pboxes in parts:
            objects[pid] = {"type": "BuildingPart", "parents": [bid], "geometry": solid(pboxes)}
    doc = {"type": "CityJSON", "version": "1.1",
           "transform": {"scale": [0.001, 0.001, 0.001], "translate": [500000.0, 5700000.0, 0.0]},
           "metadata": {"referenceSystem": "https://www.opengis.net/def/crs/EPSG/0/25832"},
           "CityObjects": objects, "vertices": vertices}
    path = tmp_path_factory.mktemp("identity_json") / "parts.city.json"
    path.write_text(json.dumps(doc))
    return path


def check_members(rows, id_field="source_id", building_field="building_id"):
    got = {r[id_field]: r[building_field] for r in rows}
    assert got == EXPECTED_MEMBERS


def check_plans(rows, ids_field="building_ids"):
    got = {r[ids_field]: r["buildings"] for r in rows}
    assert got == EXPECTED_PLANS


def items(path, layer):
    return [f for f, _ in layer_rows(path, layer)]


@pytest.mark.parametrize("src", ["city_gml", "city_json"])
@pytest.mark.parametrize("threads", ["1", "4"])
def test_cli_geopackage_names_the_buildings(tmp_path, request, src, threads):
    path = request.getfixturevalue(src)
    out = tmp_path / "o.gpkg"
    run([BIN, "--threads", threads, "-f", "GPKG", out, path, "ground_plans", "footprints", "plan_members", "problems"])
    check_plans(items(out, "ground_plans"))
    check_members(items(out, "plan_members"))
    check_members(items(out, "footprints"))


def test_cli_csv_and_shapefile_name_the_buildings(tmp_path, city_gml):
    run([BIN, "--threads", "4", "-f", "CSV", tmp_path / "p.csv", city_gml])
    with open(tmp_path / "p.csv", newline="") as f:
        check_plans(list(csv.DictReader(f)))
    run([BIN, "-f", "CSV", tmp_path / "m.csv", city_gml, "plan_members"])
    with open(tmp_path / "m.csv", newline="") as f:
        check_members(list(csv.DictReader(f)))
    shp = tmp_path / "shp"
    run([BIN, "-f", "ESRI Shapefile", shp, city_gml, "ground_plans", "plan_members"])
    check_plans(items(shp / "ground_plans.shp", "ground_plans"), ids_field="bldg_ids")
    check_members(items(shp / "plan_members.dbf", "plan_members"), building_field="bldg_id")


def test_tiled_run_names_the_buildings(tmp_path, city_gml):
    # Two tiles: HOUSE_A and HOUSE_B in different files, their parts touching across the seam.
    folder = tmp_path / "tiles"
    folder.mkdir()
    write_citygml(folder / "t1.gml", CITY[:1] + CITY[2:3], srs_name="EPSG:25832")
    write_citygml(folder / "t2.gml", CITY[1:2] + CITY[3:], srs_name="EPSG:25832")
    out = tmp_path / "tiled.gpkg"
    run([BIN, "--tiles", "on", "-f", "GPKG", out, folder, "ground_plans", "plan_members"])
    check_plans(items(out, "ground_plans"))
    check_members(items(out, "plan_members"))


def test_driver_names_the_buildings(city_gml, city_json):
    for path in (city_gml, city_json):
        ds = gdal.OpenEx(f"GROUNDPLAN:{path}", gdal.OF_VECTOR)
        check_plans([f.items() for f in ds.GetLayerByName("ground_plans")])
        check_members([f.items() for f in ds.GetLayerByName("plan_members")])
        check_members([f.items() for f in ds.GetLayerByName("footprints")])


def test_python_module_names_the_buildings(city_gml):
    if BUILD_DIR and os.path.join(BUILD_DIR, "python") not in sys.path:
        sys.path.insert(0, os.path.join(BUILD_DIR, "python"))
    groundplan = pytest.importorskip("groundplan", reason="the groundplan Python module was not built")
    r = groundplan.read(str(city_gml))
    plans = r.plans.to_dict("records") if hasattr(r.plans, "to_dict") else r.plans
    footprints = r.footprints.to_dict("records") if hasattr(r.footprints, "to_dict") else r.footprints
    check_plans(plans)
    check_members(footprints)


@pytest.mark.skipif(not (SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles").is_dir(), reason="shared data absent")
def test_niedersachsen_parts_name_their_buildings(tmp_path):
    # Real data with the geometry on BuildingParts: every part's Building is named, and differs from the part.
    folder = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    out = tmp_path / "nds.gpkg"
    run([BIN, "-f", "GPKG", out, folder, "plan_members", "ground_plans"])
    rows = items(out, "plan_members")
    parts = [r for r in rows if r["building_id"] != r["source_id"]]
    assert parts, "the sample has BuildingParts"
    ds = ogr.Open(str(out))
    plans = {f["gp_id"]: f["buildings"] for f in ds.GetLayerByName("ground_plans")}
    for r in parts:
        assert r["building_id"] in plans[r["gp_id"]].split(",")


def test_ogr_group_by_names_the_group_as_the_building(tmp_path):
    # Three 2D parts of two buildings (field "bid"): --group-by makes each group one member, named by the group.
    def square(x, y, s):
        return [[[x, y], [x + s, y], [x + s, y + s], [x, y + s], [x, y]]]
    feats = [("p1", "B1", square(500000, 5700000, 10)), ("p2", "B1", square(500010, 5700000, 10)),
             ("p3", "B2", square(500015, 5700005, 10))]
    src = tmp_path / "parts.geojson"
    src.write_text(json.dumps({"type": "FeatureCollection",
                               "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::25832"}},
                               "features": [{"type": "Feature", "properties": {"pid": p, "bid": b},
                                             "geometry": {"type": "Polygon", "coordinates": g}} for p, b, g in feats]}))
    out = tmp_path / "g.gpkg"
    run([BIN, "--group-by", "bid", "-f", "GPKG", out, src, "ground_plans", "plan_members"])
    assert sorted((r["source_id"], r["building_id"]) for r in items(out, "plan_members")) == [("B1", "B1"), ("B2", "B2")]
    assert [r["buildings"] for r in items(out, "ground_plans")] == ["B1,B2"]

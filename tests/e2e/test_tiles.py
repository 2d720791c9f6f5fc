# SPDX-License-Identifier: MIT
"""Issue 15: the tiled run (--tiles on: a tile an input file, plans crossing tile edges united again at the
end) gives the one-process plans: the same set of (rings, n_parts, area, z range, building ids), the same
(plan, fp_id, source_id) member rows and the same problems. The order of the plans differs (final plans first),
and so may the vertex a ring starts at and the order of the holes: the engine starts a ring where the ray from
its block's seed pixel meets it, and a tile's blocks and pixel size are not those of the whole input. So rings
are compared as exact vertex cycles (same coordinates as written, same orientation), rotated to their smallest
vertex, holes sorted."""
import csv
import json
import subprocess
import sys

import pytest

from conftest import BIN, LORUP, SHARED_DATA, SOURCE_DIR, run

csv.field_size_limit(1 << 30)


def ring_cycle(text):
    pts = text.strip().split(",")
    assert pts[0] == pts[-1]
    pts = pts[:-1]
    k = min(range(len(pts)), key=lambda i: tuple(map(float, pts[i].split())))
    return tuple(pts[k:] + pts[:k])


def plan_key(wkt):
    """POLYGON WKT -> (outer cycle, sorted hole cycles): equal exactly when the rings are the same cycles."""
    assert wkt.startswith("POLYGON ((") and wkt.endswith("))"), wkt[:40]
    rings = [ring_cycle(r) for r in wkt[len("POLYGON (("):-2].split("),(")]
    return rings[0], tuple(sorted(rings[1:]))


def outputs(tmp_path, name, src, *flags, launcher=()):
    """Sorted plan, member and problem rows of a CSV run, and its --stats. `launcher`: e.g. mpirun and its
    options (test_mpi.py)."""
    out = tmp_path / name
    stats = tmp_path / f"{name}.json"
    run([*launcher, BIN, "-q", "--threads", "2", "--stats", stats, *flags, "-f", "CSV", "-lco", "GEOMETRY=AS_WKT", out, src,
         "ground_plans", "plan_members", "problems"])

    def rows(layer):
        with open(out / f"{layer}.csv", newline="") as f:
            return list(csv.DictReader(f))
    plans = rows("ground_plans")
    wkt_of = {p["gp_id"]: plan_key(p["WKT"]) for p in plans}
    plan_set = sorted((plan_key(p["WKT"]), p["n_parts"], p["area_m2"], p["min_z"], p["max_z"], p["building_ids"]) for p in plans)
    members = sorted((wkt_of[m["gp_id"]], int(m["fp_id"]), m["source_id"]) for m in rows("plan_members"))
    problems = sorted((p["source_id"], p["stage"], p["code"], p["reason"]) for p in rows("problems"))
    return plan_set, members, problems, json.loads(stats.read_text())


def assert_same(one, tiled):
    assert len(one[0]) == len(tiled[0])
    assert one[0] == tiled[0], "plans differ"
    assert one[1] == tiled[1], "plan members differ"
    assert one[2] == tiled[2], "problems differ"
    t = tiled[3]["tiles"]
    assert t["final_at_once"] + t["plans_from_seams"] == len(tiled[0])
    assert t["final_at_once"] + t["seam_plans"] == t["tile_plans"]


# A generated city: courtyard blocks of four wings (the yard a hole of the plan) on a 45 m pitch, so that blocks
# cross the 100 m tile edges and corners; a row of 15 touching houses across three tiles; each building in the
# tile of its centre, one GeoJSON file a tile (EPSG:25832).
TILE = 100.0
COURTYARDS = 36
ROW = 15


def rect(x0, y0, x1, y1):
    x0, y0, x1, y1 = (500000 + x0, 5800000 + y0, 500000 + x1, 5800000 + y1)
    return [[[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]]


def generated_city(folder):
    buildings = []
    for i in range(6):
        for j in range(6):
            x0, y0 = 5 + 45 * i, 5 + 45 * j
            buildings += [(x0, y0, x0 + 30, y0 + 8), (x0, y0 + 22, x0 + 30, y0 + 30),
                          (x0, y0 + 8, x0 + 8, y0 + 22), (x0 + 22, y0 + 8, x0 + 30, y0 + 22)]
    buildings += [(20 * k, 280, 20 * k + 20, 290) for k in range(ROW)]
    tiles = {}
    for n, (x0, y0, x1, y1) in enumerate(buildings):
        key = (int((x0 + x1) / 2 // TILE), int((y0 + y1) / 2 // TILE))
        tiles.setdefault(key, []).append({"type": "Feature", "properties": {"bid": f"b{n}"},
                                          "geometry": {"type": "Polygon", "coordinates": rect(x0, y0, x1, y1)}})
    folder.mkdir()
    for (tx, ty), feats in sorted(tiles.items()):
        (folder / f"tile_{tx}_{ty}.geojson").write_text(json.dumps({
            "type": "FeatureCollection",
            "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::25832"}},
            "features": feats}))
    return len(tiles)


def test_generated_city_crossing_tile_edges(tmp_path):
    tiles = generated_city(tmp_path / "city")
    one = outputs(tmp_path, "one", tmp_path / "city", "--tiles", "off", "--id-field", "bid")
    tiled = outputs(tmp_path, "tiled", tmp_path / "city", "--tiles", "on", "--id-field", "bid")
    assert_same(one, tiled)
    # The generator's own count: one plan a courtyard block (with its yard as a hole) and one for the row.
    assert len(tiled[0]) == COURTYARDS + 1
    assert sum(1 for p in tiled[0] if len(p[0][1]) == 1) == COURTYARDS
    assert max(int(p[1]) for p in tiled[0]) == ROW
    t = tiled[3]["tiles"]
    assert t["tiles"] == tiles == 9
    assert t["seam_plans"] > 0 and t["final_at_once"] > 0
    assert "tiles" not in one[3]
    # auto: one process below 1 GiB of input (today's output, byte for byte)
    assert "tiles" not in outputs(tmp_path, "auto", tmp_path / "city", "--id-field", "bid")[3]


def test_real_niedersachsen_tiles(tmp_path):
    src = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    one = outputs(tmp_path, "one", src, "--tiles", "off")
    tiled = outputs(tmp_path, "tiled", src, "--tiles", "on")
    assert_same(one, tiled)
    assert tiled[3]["tiles"]["tiles"] == 4


def test_one_file_cut_into_interleaved_tiles(tmp_path):
    """A real file cut at member boundaries into 4 tiles: their extents overlap, so most plans are seams; the
    plans and fp_ids are those of the whole file read by one process."""
    folder = tmp_path / "cut"
    subprocess.run([sys.executable, SOURCE_DIR / "tests" / "bench" / "split_citygml_tiles.py", LORUP, "4", folder],
                   check=True, capture_output=True)
    one = outputs(tmp_path, "one", LORUP, "--tiles", "off")
    tiled = outputs(tmp_path, "tiled", folder, "--tiles", "on")
    assert one[0] == tiled[0]
    assert one[1] == tiled[1]
    assert tiled[3]["tiles"]["seam_plans"] > 0


def test_tiles_on_refuses_what_needs_everything(tmp_path):
    src = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    for flags, words in ((["--snap", "0.01"], "level of detail"), (["--verify"], "--verify")):
        p = run([BIN, "--tiles", "on", *flags, "-f", "CSV", tmp_path / "x", src], check=False)
        assert p.returncode == 1 and words in p.stderr, p.stderr
    p = run([BIN, "--tiles", "on", "-f", "CSV", tmp_path / "y", src, "footprints"], check=False)
    assert p.returncode == 1 and "footprints layer" in p.stderr, p.stderr


def test_a_bad_tile_is_a_problem_and_the_rest_is_written(tmp_path):
    """A tile that cannot be read is a problem record naming it; the other tiles' plans are all there."""
    folder = tmp_path / "tiles"
    folder.mkdir()
    for tile in sorted((SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles").glob("*.gml")):
        (folder / tile.name).symlink_to(tile)
    (folder / "LoD1_99999999_broken.gml").write_text('<?xml version="1.0"?>\n<CityModel><cityObjectMember><bldg')
    one = outputs(tmp_path, "one", folder, "--tiles", "off")
    tiled = outputs(tmp_path, "tiled", folder, "--tiles", "on")
    assert_same(one, tiled)
    whole = outputs(tmp_path, "whole", SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles", "--tiles", "on")
    assert tiled[0] == whole[0]
    assert any(p[2] == "UNREADABLE_FILE" for p in tiled[2]), tiled[2]
    assert tiled[3]["tiles"]["tiles"] == 5


def test_tiled_geopackage_stats_have_the_one_process_form(tmp_path):
    """--stats of a tiled GeoPackage run: the packed spatial index reported with the same fields as in the
    one-process run (scripts read spatial_index.read_s/write_s/commit_s from both)."""
    src = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    stats = {}
    for mode in ("off", "on"):
        s = tmp_path / f"{mode}.json"
        run([BIN, "-q", "--tiles", mode, "--stats", s, "-f", "GPKG", tmp_path / f"{mode}.gpkg", src])
        stats[mode] = json.loads(s.read_text())
    assert "tiles" in stats["on"] and "tiles" not in stats["off"]
    assert stats["on"]["spatial_index"].keys() == stats["off"]["spatial_index"].keys()
    assert stats["on"]["spatial_index"]["entries"] == stats["off"]["spatial_index"]["entries"] > 0


def test_auto_keeps_the_one_process_run_where_memory_is_not_at_stake(tmp_path):
    """--tiles auto (the default) tiles only where one process would hold over a quarter of the memory: a folder
    of four tiles gives the one-process output byte for byte, and --stats has no "tiles" section."""
    src = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    out = {}
    for name, flags in (("auto", []), ("off", ["--tiles", "off"])):
        s = tmp_path / f"{name}.json"
        run([BIN, "-q", "--stats", s, *flags, "-f", "CSV", "-lco", "GEOMETRY=AS_WKT", tmp_path / f"{name}.csv", src])
        out[name] = ((tmp_path / f"{name}.csv").read_bytes(), json.loads(s.read_text()))
    assert out["auto"][0] == out["off"][0]
    assert "tiles" not in out["auto"][1]


@pytest.mark.parametrize("tiles", ["off", "on"])
def test_first_tile_read_with_the_others_once_its_first_building_fixes_the_crs(tmp_path, tiles):
    """The working CRS is taken from the first tile's first building, so the first tile is read side by side with
    the others instead of before them (--stats reading.crs_guessed); tiles without a CRS fix none: the first is read
    alone first, as always. Either way the plans are those of the tiles read one after the other: the tiled run's
    tests above compare them with the one-process run."""
    src = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    bare = tmp_path / "bare"
    bare.mkdir()
    for f in sorted(src.glob("*.gml"))[:2]:  # the same tiles without srsName: coordinates kept as written
        text = f.read_text(encoding="utf-8")
        (bare / f.name).write_text(text.replace('srsName="urn:ogc:def:crs,crs:EPSG:6.12:25832,crs:EPSG:6.12:5783"', ""),
                                   encoding="utf-8")
    for folder, guessed in ((src, True), (bare, False)):
        stats = tmp_path / f"{folder.name}.json"
        run([BIN, "-q", "--tiles", tiles, "--threads", "2", "--stats", stats, "-f", "CSV", "-lco", "GEOMETRY=AS_WKT",
             tmp_path / f"{folder.name}.csv", folder])
        s = json.loads(stats.read_text())
        assert s["reading"]["crs_guessed"] is guessed, folder
        assert s["counts"]["ground_plans"] > 0

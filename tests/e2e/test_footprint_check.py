# SPDX-License-Identifier: MIT
"""A footprint found by decomposition is checked against the building's lowest horizontal faces: a house
(10 x 10 x 10 m) with a deck (4 x 6 m, 0.2 m thick, its underside 0.3 m above the ground) against its east wall,
one CityGML MultiSurface without semantic surfaces. The decomposition takes the deck for a balcony slab
(it hangs from the wall), so the footprint is the house's 100 m²; the deck's underside lies within 0.5 m of the
ground outside it: FOOTPRINT_MISSES_GROUND in the problems layer with the areas, and --verify says MISMATCH
(exit 3) although the plans match the footprints."""
import json

from osgeo import ogr

from conftest import BIN, run

X0, Y0 = 500000, 5400000


def _box(x0, y0, z0, x1, y1, z1):
    def c(x, y, z):
        return (x + X0, y + Y0, z)
    return [
        [c(x0, y0, z0), c(x1, y0, z0), c(x1, y0, z1), c(x0, y0, z1)],
        [c(x1, y0, z0), c(x1, y1, z0), c(x1, y1, z1), c(x1, y0, z1)],
        [c(x1, y1, z0), c(x0, y1, z0), c(x0, y1, z1), c(x1, y1, z1)],
        [c(x0, y1, z0), c(x0, y0, z0), c(x0, y0, z1), c(x0, y1, z1)],
        [c(x0, y0, z1), c(x1, y0, z1), c(x1, y1, z1), c(x0, y1, z1)],
        [c(x0, y1, z0), c(x1, y1, z0), c(x1, y0, z0), c(x0, y0, z0)],
    ]


def _citygml(faces):
    members = "".join(
        '<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension="3">'
        + " ".join(f"{x} {y} {z}" for x, y, z in f + [f[0]])
        + "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>\n"
        for f in faces)
    return f'''<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml">
<gml:boundedBy><gml:Envelope srsName="EPSG:25832" srsDimension="3"><gml:lowerCorner>{X0} {Y0} 0</gml:lowerCorner><gml:upperCorner>{X0 + 20} {Y0 + 20} 10</gml:upperCorner></gml:Envelope></gml:boundedBy>
<core:cityObjectMember><bldg:Building gml:id="house_with_deck"><bldg:lod2MultiSurface><gml:MultiSurface>
{members}</gml:MultiSurface></bldg:lod2MultiSurface></bldg:Building></core:cityObjectMember></core:CityModel>
'''


def test_a_footprint_leaving_out_ground_is_a_problem_and_no_match(tmp_path):
    src = tmp_path / "deck.gml"
    src.write_text(_citygml(_box(0, 0, 0, 10, 10, 10) + _box(10, 2, 0.3, 14, 8, 0.5)))
    out, stats = tmp_path / "o.gpkg", tmp_path / "s.json"
    p = run([BIN, "--footprints", "decompose", "--verify", "--stats", stats, "-f", "GPKG", out, src,
             "ground_plans", "problems"], check=False)
    assert p.returncode == 3, p.stdout + p.stderr
    assert "MISMATCH: 1 footprint leaves out ground the building stands on" in p.stdout, p.stdout
    v = json.loads(stats.read_text())["verify"]
    assert v["verdict"] == "mismatch" and v["footprints_missing_ground"] == 1 and v["match"] is False, v
    ds = ogr.Open(str(out))  # kept while its layer is read
    problems = [f.items() for f in ds.GetLayerByName("problems")]
    missing = [pr for pr in problems if pr["code"] == "FOOTPRINT_MISSES_GROUND"]
    assert len(missing) == 1, problems
    assert missing[0]["source_id"] == "house_with_deck", missing[0]
    assert "the footprint (100.0 m2) leaves out 24.0 m2 of ground" in missing[0]["reason"], missing[0]

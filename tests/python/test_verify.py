# SPDX-License-Identifier: MIT
"""groundplan.verify: what `groundplan --verify` says, for Shapely polygons. Where GEOS's floating-point union
keeps a hole the input covers, a MATCH with the places GEOS differs; an injected wrong plan, a MISMATCH naming
the region and the buildings. The triangles are tests/e2e/test_verify_adjudication.py's."""
from shapely import wkt
from shapely.geometry import Polygon, box

from conftest import groundplan

INVENTED_HOLE = [
    "POLYGON ((360586.3077894771 5417755.873136375, 360585.36301633436 5417754.86373152, 360586.4865900767 5417755.254967406, 360586.3077894771 5417755.873136375))",
    "POLYGON ((360586.6552124263 5417755.3685676865, 360586.4304448148 5417755.69500179, 360586.10504164774 5417755.714381656, 360586.6552124263 5417755.3685676865))",
    "POLYGON ((360586.6552124263 5417755.3685676865, 360585.36301633436 5417754.86373152, 360586.10504164774 5417755.714381656, 360586.6552124263 5417755.3685676865))",
]


def test_geos_inventing_a_hole_is_a_match_where_geos_differs():
    r = groundplan.verify([wkt.loads(w) for w in INVENTED_HOLE])
    assert r["verdict"] == "match_geos_differs", r
    assert r["match"] is True
    assert r["line"].startswith("MATCH: GEOS differs in 1 place, each decided in our favour: largest "), r["line"]
    assert r["holes_geos_artifacts"] == 1 and r["holes"] == 0 and r["places_ours_wrong"] == 0, r


def test_the_union_itself_is_a_plain_match():
    r = groundplan.verify([box(0, 0, 10, 10), box(10, 0, 20, 10)])
    assert r["verdict"] == "match" and r["line"] == "MATCH", r


def test_a_wrong_plan_is_a_mismatch_naming_region_and_building():
    houses = [box(500000, 5400000, 500010, 5400010), box(500010, 5400000, 500020, 5400010)]
    wrong = Polygon(box(500000, 5400000, 500020, 5400010).exterior.coords,
                    [box(500012, 5400002, 500014, 5400004).exterior.coords])
    r = groundplan.verify(houses, [wrong], [[0, 1]], ids=["west", "east"])
    assert r["verdict"] == "mismatch" and r["match"] is False, r
    assert r["places_ours_wrong"] == 1 and abs(r["largest_ours_wrong_m2"] - 4) < 1e-6, r
    assert "the input covers and our plans do not" in r["line"] and "buildings east" in r["line"], r["line"]

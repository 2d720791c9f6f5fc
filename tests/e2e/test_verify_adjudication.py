# SPDX-License-Identifier: MIT
"""`--verify` decides every difference with GEOS exactly against the input footprints: where GEOS's
floating-point union keeps a hole of 2.5e-12 m² that the input covers, the run still MATCHes (exit 0) and
says where GEOS differs, in the output line and in --stats. The input (five triangles, 0.46 m², near
(360586, 5417755), UTM 32N; two of them without area) was found by tests/bench/geos_disagreement_search
(--min-size 0.05); GDAL writes it here (GeoPackage doubles: exact)."""
import json

from osgeo import ogr, osr

from conftest import BIN, run

INVENTED_HOLE = [
    "POLYGON ((360586.3077894771 5417755.873136375, 360585.36301633436 5417754.86373152, 360586.4865900767 5417755.254967406, 360586.3077894771 5417755.873136375))",
    "POLYGON ((360586.6552124263 5417755.3685676865, 360586.4304448148 5417755.69500179, 360586.10504164774 5417755.714381656, 360586.6552124263 5417755.3685676865))",
    "POLYGON ((360585.36301633436 5417754.86373152, 360585.8638604412 5417754.972518185, 360585.8638604412 5417754.972518185, 360585.36301633436 5417754.86373152))",
    "POLYGON ((360586.6552124263 5417755.3685676865, 360585.36301633436 5417754.86373152, 360586.10504164774 5417755.714381656, 360586.6552124263 5417755.3685676865))",
    "POLYGON ((360586.3077894771 5417755.873136375, 360586.3077894771 5417755.873136375, 360587.26946022216 5417756.626139601, 360586.3077894771 5417755.873136375))",
]


def _write_gpkg(path, wkts):
    ds = ogr.GetDriverByName("GPKG").CreateDataSource(str(path))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32632)
    lyr = ds.CreateLayer("buildings", srs, ogr.wkbPolygon)
    for w in wkts:
        f = ogr.Feature(lyr.GetLayerDefn())
        f.SetGeometry(ogr.CreateGeometryFromWkt(w))
        lyr.CreateFeature(f)
    ds = None


def test_geos_inventing_a_hole_is_a_match_with_the_adjudication_line(tmp_path):
    src = tmp_path / "triangles.gpkg"
    _write_gpkg(src, INVENTED_HOLE)
    stats = tmp_path / "stats.json"
    p = run([BIN, "--verify", "--stats", stats, "-f", "GPKG", tmp_path / "o.gpkg", src])
    assert p.returncode == 0
    assert "MATCH: GEOS differs in 1 place, each decided in our favour: largest " in p.stdout, p.stdout
    assert "MISMATCH" not in p.stdout
    v = json.loads(stats.read_text())["verify"]
    assert v["verdict"] == "match_geos_differs" and v["match"] is True, v
    assert v["holes_geos_artifacts"] == 1 and v["holes"] == 0, v
    assert v["places_geos_wrong"] == 1 and 0 < v["largest_geos_wrong_m2"] < 1e-10, v
    assert v["places_ours_wrong"] == 0, v

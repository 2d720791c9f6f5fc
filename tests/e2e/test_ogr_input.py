# SPDX-License-Identifier: MIT
"""Any OGR layer as input (issue 22). The inputs are written by GDAL itself (ogr2ogr, the OGR Python API),
not by us: the footprints of real CityGML samples as Shapefile, GeoPackage, GeoJSON and FlatGeobuf must give
exactly the plans of the CityGML; building solids read by GDAL's GML driver and written as a MultiPatch
shapefile and a PolyhedralSurface GeoPackage must give the plans of the CityGML with --footprints decompose;
a generated OSM file must give GEOS's union; hostile inputs give named problems and lose no feature."""
import json
import math
import pathlib
import re

import pytest
from osgeo import gdal, ogr, osr

from conftest import BIN, PLATEAU, SHARED_DATA, run

LORUP_TILES = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
FORMATS = {  # ogr2ogr -f name, extension, extra layer creation options
    "shp": ("ESRI Shapefile", ".shp", []),
    "gpkg": ("GPKG", ".gpkg", []),
    "geojson": ("GeoJSON", ".geojson", []),
    "fgb": ("FlatGeobuf", ".fgb", []),
}


def plans(path):
    """{(WKT, sorted building ids)} of the ground_plans layer."""
    ds = ogr.Open(str(path))
    out = set()
    for f in ds.GetLayerByName("ground_plans"):
        out.add((f.GetGeometryRef().ExportToIsoWkt(), tuple(sorted(f["building_ids"].split(",")))))
    return out


def layer_items(path, name):
    ds = ogr.Open(str(path))
    return [f.items() for f in ds.GetLayerByName(name)]


def need(path):
    if not path.exists():
        pytest.skip(f"{path} is not here")


@pytest.fixture(scope="module")
def city_footprints(tmp_path_factory):
    """The CityGML runs (Niiza sample, the four Lorup tiles as one folder): plans and footprints."""
    d = tmp_path_factory.mktemp("city")
    out = {}
    for name, src in {"niiza": PLATEAU, "lorup": LORUP_TILES}.items():
        if not src.exists():
            continue
        run([BIN, "-f", "GPKG", d / f"{name}.gpkg", src, "ground_plans", "footprints"])
        out[name] = d / f"{name}.gpkg"
    return out


@pytest.mark.parametrize("fmt", sorted(FORMATS))
@pytest.mark.parametrize("sample", ["niiza", "lorup"])
def test_2d_footprints_written_by_gdal_give_the_citygml_plans(tmp_path, city_footprints, fmt, sample):
    if sample not in city_footprints:
        pytest.skip(f"{sample} sample is not here")
    city = city_footprints[sample]
    driver, ext, lco = FORMATS[fmt]
    src = tmp_path / f"footprints{ext}"
    run(["ogr2ogr", "-f", driver, *lco, src, city, "footprints"])
    out = tmp_path / "plans.gpkg"
    run([BIN, "--id-field", "source_id", "--stats", tmp_path / "s.json", "-f", "GPKG", out, src,
         "ground_plans", "problems", "footprints"])
    expected = plans(city)
    assert len(expected) > 50
    assert plans(out) == expected  # same WKT, bit for bit, and the same buildings in each plan
    n_features = len(layer_items(city, "footprints"))
    fps = layer_items(out, "footprints")
    assert len(fps) == n_features and {f["method"] for f in fps} == {"lod0-footprint"}
    assert [p for p in layer_items(out, "problems") if p["code"] != "NOTE"] == []
    stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["counts"]["buildings"] == n_features


def test_a_zipped_shapefile_is_read_by_gdal_not_taken_for_a_kmz(tmp_path, city_footprints):
    import zipfile
    city = city_footprints["niiza"]
    run(["ogr2ogr", "-f", "ESRI Shapefile", tmp_path / "fp.shp", city, "footprints"])
    src = tmp_path / "fp.shp.zip"
    with zipfile.ZipFile(src, "w") as z:
        for ext in (".shp", ".shx", ".dbf", ".prj"):
            z.write(tmp_path / f"fp{ext}", f"fp{ext}")
    out = tmp_path / "o.gpkg"
    run([BIN, "--id-field", "source_id", "-f", "GPKG", out, src])
    assert plans(out) == plans(city)


def test_the_driver_reads_ogr_sources_with_open_options(tmp_path, city_footprints):
    """GROUNDPLAN:<shapefile> through GDAL's own ogr2ogr, with INPUT_WHERE and ID_FIELD."""
    city = city_footprints["niiza"]
    src = tmp_path / "fp.gpkg"
    run(["ogr2ogr", "-f", "GPKG", src, city, "footprints"])
    out = tmp_path / "o.gpkg"
    run(["ogr2ogr", "-f", "GPKG", "-oo", "ID_FIELD=source_id", "-oo", "INPUT_LAYERS=footprints",
         "-oo", "INPUT_WHERE=fp_id <= 100", out, f"GROUNDPLAN:{src}", "ground_plans", "footprints"])
    ids = {f["source_id"] for f in layer_items(out, "footprints")}
    want = {f["source_id"] for f in layer_items(city, "footprints") if f["fp_id"] <= 100}
    assert ids == want and len(ids) == 100


def test_our_own_driver_is_never_an_input(tmp_path, city_footprints):
    """GROUNDPLAN:x as a source would run the pipeline inside the reader (plans of plans, or recursion):
    GDAL's identify runs without our driver, so it is refused."""
    src = tmp_path / "fp.gpkg"
    run(["ogr2ogr", "-f", "GPKG", src, city_footprints["niiza"], "footprints"])
    p = run([BIN, "-f", "GPKG", tmp_path / "x.gpkg", f"GROUNDPLAN:{src}"], check=False)
    assert p.returncode == 1 and "format not recognised" in p.stderr and f"GROUNDPLAN:{src}" in p.stderr


def test_input_sql_and_a_missing_layer_or_field(tmp_path, city_footprints):
    city = city_footprints["niiza"]
    src = tmp_path / "fp.gpkg"
    run(["ogr2ogr", "-f", "GPKG", src, city, "footprints"])
    out = tmp_path / "o.gpkg"
    run([BIN, "--input-sql", "SELECT * FROM footprints WHERE fp_id > 600", "--id-field", "source_id",
         "-f", "GPKG", out, src, "footprints"])
    assert len(layer_items(out, "footprints")) == len(layer_items(city, "footprints")) - 600
    p = run([BIN, "--input-layer", "nope", "-f", "GPKG", tmp_path / "x.gpkg", src], check=False)
    assert p.returncode == 1 and "has no layer 'nope'" in p.stderr and "footprints" in p.stderr
    p = run([BIN, "--id-field", "nope", "-f", "GPKG", tmp_path / "x.gpkg", src], check=False)
    assert p.returncode == 1 and "has no field 'nope'" in p.stderr and str(src) in p.stderr


def _geos_match(ours, ref):
    """Every plan of `ref` has one in `ours` whose symmetric difference is under 1e-9 of its area, and back."""
    def geoms(path):
        ds = ogr.Open(str(path))  # held: a layer dies with its dataset
        return [f.GetGeometryRef().Clone() for f in ds.GetLayerByName("ground_plans")]
    a, b = geoms(ours), geoms(ref)
    assert len(a) == len(b)
    assert sum(g.GetGeometryCount() - 1 for g in a) == sum(g.GetGeometryCount() - 1 for g in b)  # holes
    total = sum(g.GetArea() for g in b)
    union_a = ogr.Geometry(ogr.wkbMultiPolygon)
    union_b = ogr.Geometry(ogr.wkbMultiPolygon)
    for g in a:
        union_a.AddGeometry(g)
    for g in b:
        union_b.AddGeometry(g)
    assert union_a.SymDifference(union_b).GetArea() < 1e-9 * total


@pytest.mark.parametrize("kind", ["multipatch", "polyhedralsurface"])
def test_solids_written_by_gdal_give_the_decomposed_citygml_plans(tmp_path, kind):
    """GDAL's GML driver reads the Niiza LoD1 solids (as PolyhedralSurface, EPSG:6668 in lon/lat order); ogr2ogr
    writes them as a MultiPatch shapefile or a PolyhedralSurface GeoPackage. Not bit-identical to the CityGML
    route: GDAL's CRS (6668, the horizontal part of the file's 6697) takes another PROJ path, and coordinates
    differ in the last bits (1e-9 m); hence GEOS's symmetric difference, and the same counts."""
    src = tmp_path / ("solids.shp" if kind == "multipatch" else "solids.gpkg")
    args = ["-lco", "SHPT=MULTIPATCH"] if kind == "multipatch" else ["-nlt", "POLYHEDRALSURFACEZ"]
    run(["ogr2ogr", "-f", "ESRI Shapefile" if kind == "multipatch" else "GPKG", *args, "-select", "gml_id",
         "-oo", "WRITE_GFS=NO", src, PLATEAU, "Building"])  # no .gfs beside the sample
    ref = tmp_path / "ref.gpkg"
    run([BIN, "--footprints", "decompose", "-f", "GPKG", ref, PLATEAU, "ground_plans", "footprints"])
    out = tmp_path / "out.gpkg"
    run([BIN, "--footprints", "decompose", "--id-field", "gml_id", "-f", "GPKG", out, src, "ground_plans",
         "footprints", "problems"])
    fps = layer_items(out, "footprints")
    assert len(fps) == 657 and {f["method"] for f in fps} <= {"decomposition", "decomposition-shadow"}
    assert {f["source_id"] for f in fps} == {f["source_id"] for f in layer_items(ref, "footprints")}  # gml:ids
    _geos_match(out, ref)
    # The explicit path (the solid's bottom) gives the same plans.
    out2 = tmp_path / "out2.gpkg"
    run([BIN, "-f", "GPKG", out2, src, "ground_plans", "footprints"])
    assert {f["method"] for f in layer_items(out2, "footprints")} == {"solid-bottom"}
    _geos_match(out2, ref)


def _osm_xml():
    """Buildings around (139.55, 35.75): a block of three overlapping building:parts sharing a name, a
    multipolygon building with a courtyard, and two plain buildings that touch along a wall."""
    nodes, ways, rels = [], [], []
    nid = [0]

    def node(x_m, y_m):
        nid[0] += 1
        lon = 139.55 + x_m / 90400.0
        lat = 35.75 + y_m / 111000.0
        nodes.append(f'<node id="{nid[0]}" version="1" lat="{lat:.9f}" lon="{lon:.9f}"/>')
        return nid[0]

    def way(wid, pts, tags):
        ids = [node(x, y) for x, y in pts]
        refs = "".join(f'<nd ref="{i}"/>' for i in ids + ids[:1])
        t = "".join(f'<tag k="{k}" v="{v}"/>' for k, v in tags.items())
        ways.append(f'<way id="{wid}" version="1">{refs}{t}</way>')

    def rect(x0, y0, x1, y1):
        return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]

    way(1, rect(0, 0, 30, 20), {"building": "yes", "name": "hall"})
    way(2, rect(20, 10, 40, 30), {"building:part": "yes", "name": "hall"})
    way(3, rect(35, 25, 50, 40), {"building:part": "yes", "name": "hall"})
    way(4, rect(100, 0, 160, 60), {})
    way(5, rect(120, 20, 140, 40), {})
    rels.append('<relation id="10" version="1"><member type="way" ref="4" role="outer"/>'
                '<member type="way" ref="5" role="inner"/><tag k="type" v="multipolygon"/>'
                '<tag k="building" v="yes"/><tag k="name" v="court"/></relation>')
    way(6, rect(0, 100, 20, 120), {"building": "house", "name": "house"})
    way(7, rect(20, 100, 40, 115), {"building": "garage", "name": "garage"})
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<osm version="0.6" generator="groundplan-test">\n'
            + "\n".join(nodes + ways + rels) + "\n</osm>\n")


def _osm_config(tmp_path):
    """GDAL's osmconf.ini with building:part among the tags that make a closed way a polygon (GDAL 3.6 lists
    only building: its parts would land in the 'lines' layer) and as a field of 'multipolygons'."""
    text = pathlib.Path(gdal.FindFile("gdal", "osmconf.ini")).read_text()
    text = text.replace("closed_ways_are_polygons=aeroway,amenity,boundary,building,",
                        "closed_ways_are_polygons=aeroway,amenity,boundary,building,building:part,", 1)
    text = re.sub(r"(\[multipolygons\][^\[]*?attributes=name,)", r"\1building:part,", text, count=1)
    assert "building,building:part," in text and "attributes=name,building:part," in text
    path = tmp_path / "osmconf.ini"
    path.write_text(text)
    return path


def test_osm_buildings_parts_and_courtyards_match_geos(tmp_path):
    src = tmp_path / "city.osm"
    src.write_text(_osm_xml())
    conf = _osm_config(tmp_path)
    out = tmp_path / "o.gpkg"
    run([BIN, "--input-layer", "multipolygons", "--input-oo", f"CONFIG_FILE={conf}", "--group-by", "name",
         "--verify", "-f", "GPKG", out, src, "ground_plans", "footprints", "problems"])
    out_ds = ogr.Open(str(out))
    plans_ = [f for f in out_ds.GetLayerByName("ground_plans")]
    by_ids = {f["building_ids"]: f for f in plans_}
    # hall: one building of three parts; court: one with a courtyard hole; house + garage touch: one plan.
    assert set(by_ids) == {"hall", "court", "house,garage"}
    assert by_ids["court"].GetGeometryRef().GetGeometryCount() == 2  # outer + courtyard
    assert len(layer_items(out, "footprints")) == 4  # hall (3 parts), court, house, garage
    assert [p for p in layer_items(out, "problems") if p["code"] != "NOTE"] == []
    # Without --group-by each part is a building of its own, and the plan still unites them.
    out2 = tmp_path / "o2.gpkg"
    run([BIN, "--input-layer", "multipolygons", "--input-oo", f"CONFIG_FILE={conf}", "-f", "GPKG", out2, src])
    assert sorted(f["n_parts"] for f in layer_items(out2, "ground_plans")) == [1, 2, 3]
    # GEOS's union of GDAL's own polygons, transformed like ours, is the reference.
    ds = gdal.OpenEx(str(src), gdal.OF_VECTOR, open_options=[f"CONFIG_FILE={conf}"])
    lyr = ds.GetLayerByName("multipolygons")
    dst = out_ds.GetLayerByName("ground_plans").GetSpatialRef().Clone()
    src_srs = lyr.GetSpatialRef().Clone()
    src_srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    dst.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    ct = osr.CoordinateTransformation(src_srs, dst)
    coll = ogr.Geometry(ogr.wkbMultiPolygon)
    n = 0
    for f in lyr:
        n += 1
        g = f.GetGeometryRef().Clone()
        g.Transform(ct)
        for i in range(g.GetGeometryCount()):
            coll.AddGeometry(g.GetGeometryRef(i))
    assert n == 6
    union = coll.UnionCascaded()
    ours = ogr.Geometry(ogr.wkbMultiPolygon)
    for f in plans_:
        ours.AddGeometry(f.GetGeometryRef())
    assert union.GetGeometryCount() == len(plans_) == 3
    assert union.SymDifference(ours).GetArea() < 1e-9 * union.GetArea()


def _hostile_gpkg(path):
    """One GeoPackage written by GDAL: a layer of parts with every defect beside good polygons, a layer of lines."""
    ds = ogr.GetDriverByName("GPKG").CreateDataSource(str(path))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(25832)
    parts = ds.CreateLayer("parts", srs, ogr.wkbUnknown)
    parts.CreateField(ogr.FieldDefn("name", ogr.OFTString))
    wkts = {
        "good-a": "POLYGON ((400000 5800000,400010 5800000,400010 5800010,400000 5800010,400000 5800000))",
        "good-b": "POLYGON ((400005 5800005,400015 5800005,400015 5800015,400005 5800015,400005 5800005))",
        "good-c": "MULTIPOLYGON (((400100 5800000,400110 5800000,400110 5800010,400100 5800000)))",
        "bowtie": "POLYGON ((400200 5800000,400220 5800010,400220 5800000,400200 5800005,400200 5800000))",
        "curve": "CURVEPOLYGON (CIRCULARSTRING (400300 5800000,400310 5800010,400300 5800020,400290 5800010,"
                 "400300 5800000))",
        "empty": "POLYGON EMPTY",
        "point": "POINT (400400 5800000)",
        "huge": "POLYGON ((1e12 0,1e12 1,1e12 2,1e12 0))",
    }
    for name, wkt in list(wkts.items()) + [("null", None), ("nan", "nan")]:
        f = ogr.Feature(parts.GetLayerDefn())
        f["name"] = name
        if wkt == "nan":
            g = ogr.Geometry(ogr.wkbPolygon)
            r = ogr.Geometry(ogr.wkbLinearRing)
            for x, y in [(400500, 5800000), (math.nan, 5800000), (400510, 5800010), (400500, 5800000)]:
                r.AddPoint_2D(x, y)
            g.AddGeometry(r)
            f.SetGeometry(g)
        elif wkt:
            f.SetGeometry(ogr.CreateGeometryFromWkt(wkt))
        parts.CreateFeature(f)
    roads = ds.CreateLayer("roads", srs, ogr.wkbLineString)
    for i in range(2):
        f = ogr.Feature(roads.GetLayerDefn())
        f.SetGeometry(ogr.CreateGeometryFromWkt(f"LINESTRING (400000 {5800100 + i},400100 {5800100 + i})"))
        roads.CreateFeature(f)
    ds = None


def test_hostile_features_are_named_problems_and_nothing_is_lost(tmp_path):
    src = tmp_path / "hostile.gpkg"
    _hostile_gpkg(src)
    out = tmp_path / "o.gpkg"
    run([BIN, "--id-field", "name", "--stats", tmp_path / "s.json", "-f", "GPKG", out, src, "ground_plans",
         "footprints", "problems"])
    fps = {f["source_id"] for f in layer_items(out, "footprints")}
    assert fps == {"good-a", "good-b", "good-c", "bowtie", "curve"}
    problems = {p["source_id"]: p for p in layer_items(out, "problems") if p["code"] != "NOTE"}
    codes = {k: p["code"] for k, p in problems.items()}
    assert codes == {"empty": "EMPTY_GEOMETRY", "null": "EMPTY_GEOMETRY", "point": "NOT_AREAL",
                     "nan": "BAD_COORDINATES", "huge": "COORDINATE_OUT_OF_RANGE",
                     "roads:1": "NOT_AREAL", "roads:2": "NOT_AREAL"}
    for p in problems.values():  # each names the file, the layer and the FID
        assert p["file"] == str(src) and "layer '" in p["reason"] and "FID " in p["reason"]
    # features = members + problems
    src_ds = ogr.Open(str(src))
    n_features = sum(src_ds.GetLayer(i).GetFeatureCount() for i in range(2))
    assert n_features == len(fps) + len(problems) == 12
    stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["counts"]["buildings"] == 12 and stats["counts"]["dropped"] == 7
    # The invalid bowtie went to the union as it is: one plan holds it (two triangles touching at a point).
    plans_ = layer_items(out, "ground_plans")
    assert any(p["building_ids"] == "bowtie" for p in plans_)
    assert any(p["building_ids"] == "good-a,good-b" for p in plans_)


def test_shapefile_with_a_cut_short_shx_is_named_and_the_other_inputs_are_read(tmp_path):
    shp = tmp_path / "cut.shp"
    good = tmp_path / "good.geojson"
    for path, drv in ((shp, "ESRI Shapefile"), (good, "GeoJSON")):
        ds = ogr.GetDriverByName(drv).CreateDataSource(str(path))
        srs = osr.SpatialReference()
        srs.ImportFromEPSG(25832)
        lyr = ds.CreateLayer(path.stem, srs, ogr.wkbPolygon)
        for i in range(10):
            f = ogr.Feature(lyr.GetLayerDefn())
            x = 400000 + 20 * i
            f.SetGeometry(ogr.CreateGeometryFromWkt(
                f"POLYGON (({x} 5800000,{x + 10} 5800000,{x + 10} 5800010,{x} 5800010,{x} 5800000))"))
            lyr.CreateFeature(f)
        ds = None
    shx = tmp_path / "cut.shx"
    shx.write_bytes(shx.read_bytes()[:136])  # header + 4.5 of 10 records
    p = run([BIN, "-f", "GPKG", tmp_path / "x.gpkg", shp], check=False)
    assert p.returncode == 1 and str(shp) in p.stderr and ".shx" in p.stderr and "SHAPE_RESTORE_SHX" in p.stderr
    out = tmp_path / "o.gpkg"
    run(["ogr2ogr", "-f", "GPKG", out, f"GROUNDPLAN:{shp},{good}", "ground_plans", "problems"])
    assert len(layer_items(out, "ground_plans")) == 10
    bad = [q for q in layer_items(out, "problems") if q["code"] == "UNREADABLE_FILE"]
    assert len(bad) == 1 and bad[0]["file"] == str(shp)


def test_a_million_vertex_ring_in_geojson_ends_with_its_plan(tmp_path):
    n = 1_000_000
    ring = [[400000 + 100 * math.cos(2 * math.pi * k / n), 5800000 + 100 * math.sin(2 * math.pi * k / n)]
            for k in range(n)]
    ring.append(ring[0])
    doc = {"type": "FeatureCollection",
           "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::25832"}},
           "features": [{"type": "Feature", "properties": {"name": "ring"},
                         "geometry": {"type": "Polygon", "coordinates": [ring]}},
                        {"type": "Feature", "properties": {"name": "line"},
                         "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}}]}
    src = tmp_path / "huge.geojson"
    src.write_text(json.dumps(doc))
    out = tmp_path / "o.gpkg"
    run([BIN, "--id-field", "name", "-f", "GPKG", out, src, "ground_plans", "problems"])  # a hang: run()'s timeout
    plans_ = layer_items(out, "ground_plans")
    assert len(plans_) == 1 and plans_[0]["building_ids"] == "ring"
    assert abs(plans_[0]["area_m2"] - math.pi * 100 ** 2) < 1
    assert [(q["source_id"], q["code"]) for q in layer_items(out, "problems") if q["code"] != "NOTE"] == \
        [("line", "NOT_AREAL")]


def test_a_folder_of_shapefiles_and_geopackages_is_one_input(tmp_path, city_footprints):
    """A folder of OGR files is read like a folder of tiles: each .shp/.gpkg/.fgb/.geojson is an input, sorted by
    name; a shapefile's .dbf/.shx/.prj/.cpg are not inputs of their own. The plans are those of the whole."""
    city = city_footprints["lorup"] if "lorup" in city_footprints else city_footprints["niiza"]
    folder = tmp_path / "parts"
    folder.mkdir()
    n = len(layer_items(city, "footprints"))
    cuts = [0, n // 3, 2 * n // 3, n]
    for k, (drv, ext, lco) in enumerate([("ESRI Shapefile", ".shp", ["-lco", "ENCODING=UTF-8"]),  # + a .cpg
                                         ("ESRI Shapefile", ".shp", []), ("GPKG", ".gpkg", [])]):
        run(["ogr2ogr", "-f", drv, *lco, folder / f"part{k}{ext}", city, "footprints", "-where",
             f"fid > {cuts[k]} AND fid <= {cuts[k + 1]}", "-nln", f"part{k}"])
    (folder / "notes.txt").write_text("not an input")
    assert {p.suffix for p in folder.iterdir()} >= {".shp", ".dbf", ".shx", ".prj", ".cpg", ".gpkg", ".txt"}
    out = tmp_path / "plans.gpkg"
    run([BIN, "--id-field", "source_id", "--stats", tmp_path / "s.json", "-f", "GPKG", out, folder,
         "ground_plans", "problems"])
    stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["reading"]["files"] == 3 and stats["counts"]["buildings"] == n
    assert plans(out) == plans(city)
    assert [p for p in layer_items(out, "problems") if p["code"] != "NOTE"] == []
    # A folder of sidecars only is refused, the message naming what a folder may hold.
    for p in folder.glob("*.shp"):
        p.unlink()
    for p in folder.glob("*.gpkg"):
        p.unlink()
    r = run([BIN, "-f", "GPKG", tmp_path / "x.gpkg", folder], check=False)
    assert r.returncode == 1 and "folder holds no input file" in r.stderr and "*.shp" in r.stderr
    assert "*.city.json.gz" in r.stderr  # every name a folder is expanded to, compressed ones too


def _two_geometry_sqlite(path):
    """An SQLite table (GDAL's SQLite driver keeps several geometry columns) with a footprint and a roof column."""
    ds = ogr.GetDriverByName("SQLite").CreateDataSource(str(path))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(25832)
    lyr = ds.CreateLayer("houses", None, ogr.wkbNone)
    for name in ("footprint", "roof"):
        gfd = ogr.GeomFieldDefn(name, ogr.wkbPolygon)
        gfd.SetSpatialRef(srs)
        lyr.CreateGeomField(gfd)
    lyr.CreateField(ogr.FieldDefn("name", ogr.OFTString))
    for i in range(3):
        f = ogr.Feature(lyr.GetLayerDefn())
        f["name"] = f"h{i}"
        x = 400000 + 30 * i
        f.SetGeomField(0, ogr.CreateGeometryFromWkt(
            f"POLYGON (({x} 5800000,{x + 10} 5800000,{x + 10} 5800010,{x} 5800010,{x} 5800000))"))
        f.SetGeomField(1, ogr.CreateGeometryFromWkt(  # the roof overhangs: 12 x 12
            f"POLYGON (({x - 1} 5799999,{x + 11} 5799999,{x + 11} 5800011,{x - 1} 5800011,{x - 1} 5799999))"))
        lyr.CreateFeature(f)
    ds = None


def test_a_layer_with_several_geometry_fields_reads_the_first_or_the_one_named(tmp_path):
    src = tmp_path / "houses.sqlite"
    _two_geometry_sqlite(src)
    out = tmp_path / "first.gpkg"
    run([BIN, "--id-field", "name", "-f", "GPKG", out, src, "ground_plans", "problems"])
    assert sorted(round(p["area_m2"]) for p in layer_items(out, "ground_plans")) == [100, 100, 100]
    notes = [p["reason"] for p in layer_items(out, "problems") if p["code"] == "NOTE"]
    assert any("2 geometry fields ('footprint', 'roof'): only 'footprint' is read" in n for n in notes), notes
    out = tmp_path / "roof.gpkg"
    run([BIN, "--id-field", "name", "--input-geom-field", "roof", "-f", "GPKG", out, src, "ground_plans", "problems"])
    assert sorted(round(p["area_m2"]) for p in layer_items(out, "ground_plans")) == [144, 144, 144]
    notes = [p["reason"] for p in layer_items(out, "problems") if p["code"] == "NOTE"]
    assert any("only 'roof' is read" in n for n in notes), notes
    # The driver's open option, through GDAL's own ogr2ogr.
    out = tmp_path / "driver.gpkg"
    run(["ogr2ogr", "-f", "GPKG", "-oo", "INPUT_GEOM_FIELD=roof", "-oo", "ID_FIELD=name", out, f"GROUNDPLAN:{src}",
         "ground_plans"])
    assert sorted(round(p["area_m2"]) for p in layer_items(out, "ground_plans")) == [144, 144, 144]
    r = run([BIN, "--input-geom-field", "walls", "-f", "GPKG", tmp_path / "x.gpkg", src], check=False)
    assert r.returncode == 1 and str(src) in r.stderr and "no geometry field 'walls'" in r.stderr
    assert "'footprint', 'roof'" in r.stderr


def _ten_squares_shapefile(path):
    ds = ogr.GetDriverByName("ESRI Shapefile").CreateDataSource(str(path))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(25832)
    lyr = ds.CreateLayer(path.stem, srs, ogr.wkbPolygon)
    lyr.CreateField(ogr.FieldDefn("name", ogr.OFTString))
    for i in range(10):
        f = ogr.Feature(lyr.GetLayerDefn())
        f["name"] = f"b{i}"
        x = 400000 + 20 * i
        f.SetGeometry(ogr.CreateGeometryFromWkt(
            f"POLYGON (({x} 5800000,{x + 10} 5800000,{x + 10} 5800010,{x} 5800010,{x} 5800000))"))
        lyr.CreateFeature(f)
    ds = None


@pytest.mark.parametrize("threads", ["1", "3"])
def test_a_dbf_cut_short_mid_record_stops_the_layer_with_unreadable_features(tmp_path, threads):
    """The .dbf ends inside record 5 of 10: GDAL fails there and gives no more features. The layer's problem says
    how many were read and how many the layer counts; the features read are all members (features = members +
    problems), and the run with ranges on 3 threads gives up its ranges and says the same."""
    shp = tmp_path / "cut.shp"
    _ten_squares_shapefile(shp)
    dbf = tmp_path / "cut.dbf"
    data = dbf.read_bytes()
    header_len = int.from_bytes(data[8:10], "little")
    record_len = int.from_bytes(data[10:12], "little")
    dbf.write_bytes(data[:header_len + 4 * record_len + record_len // 2])
    out = tmp_path / "o.gpkg"
    run([BIN, "--id-field", "name", "--threads", threads, "--read-range-features", "2", "--stats", tmp_path / "s.json",
         "-f", "GPKG", out, shp, "footprints", "problems"])
    fps = [f["source_id"] for f in layer_items(out, "footprints")]
    problems = [p for p in layer_items(out, "problems") if p["code"] != "NOTE"]
    assert fps == ["b0", "b1", "b2", "b3"]
    assert [p["code"] for p in problems] == ["UNREADABLE_FEATURES"]
    reason = problems[0]["reason"]
    assert problems[0]["file"] == str(shp) and "layer 'cut'" in reason and "DBF" in reason
    assert "after 4 features of the 10 the layer counts" in reason
    features_read = int(re.search(r"after (\d+) features", reason).group(1))
    assert features_read == len(fps) + len([p for p in problems if p["source_id"]])  # features = members + problems
    stats = json.loads((tmp_path / "s.json").read_text())
    if threads == "3":
        assert stats["reading"]["chunks"] == 0 and "range" in stats["reading"]["read_whole"][0]["why"]


def test_a_shp_cut_short_mid_record_names_each_feature_left_without_geometry(tmp_path):
    """The .shp ends inside record 7 (the .shx and .dbf whole): GDAL gives features 6-9 without geometry, each
    an EMPTY_GEOMETRY problem naming its FID and GDAL's fread error; nothing is dropped silently."""
    shp = tmp_path / "cut.shp"
    _ten_squares_shapefile(shp)
    data = shp.read_bytes()
    record = (len(data) - 100) // 10
    shp.write_bytes(data[:100 + 6 * record + record // 2])
    out = tmp_path / "o.gpkg"
    run([BIN, "--id-field", "name", "-f", "GPKG", out, shp, "footprints", "problems"])
    fps = [f["source_id"] for f in layer_items(out, "footprints")]
    problems = [p for p in layer_items(out, "problems") if p["code"] != "NOTE"]
    assert fps == [f"b{i}" for i in range(6)]
    assert [(p["source_id"], p["code"]) for p in problems] == [(f"b{i}", "EMPTY_GEOMETRY") for i in range(6, 10)]
    assert all(f"FID {i}" in p["reason"] and "fread" in p["reason"] for i, p in zip(range(6, 10), problems))
    assert len(fps) + len(problems) == 10

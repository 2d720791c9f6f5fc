#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the bad-input corpus (issue 8): one defect per file, named by its defect. The files are
committed; run this only to change them (python3 tests/corpus/bad/make_corpus.py). Expected outcomes
are in expected.json beside them, checked by tests/e2e/test_bad_input.py through the real CLI."""
import pathlib
import random

HERE = pathlib.Path(__file__).parent

NS = ('xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" '
      'xmlns:gml="http://www.opengis.net/gml" xmlns:xlink="http://www.w3.org/1999/xlink"')
SRS = "EPSG:25832"


def ring(points, dim=3):
    return " ".join(" ".join(repr(float(c)) for c in p[:dim]) for p in points + [points[0]])


def polygon(points, pid=None, poslist=None):
    attr = f' gml:id="{pid}"' if pid else ""
    text = poslist if poslist is not None else ring(points)
    return (f'<gml:surfaceMember><gml:Polygon{attr}><gml:exterior><gml:LinearRing>'
            f'<gml:posList srsDimension="3">{text}</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>'
            f'</gml:surfaceMember>\n')


def box_faces(x0, y0, w=10.0, d=8.0, z0=40.0, z1=48.0):
    x1, y1 = x0 + w, y0 + d
    b = [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)]  # bottom, facing down
    t = [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    walls = [[(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],
             [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],
             [(x1, y1, z0), (x0, y1, z0), (x0, y1, z1), (x1, y1, z1)],
             [(x0, y1, z0), (x0, y0, z0), (x0, y0, z1), (x0, y1, z1)]]
    return [b, t] + walls


def building(bid, x0, y0, faces=None, extra=""):
    faces = box_faces(x0, y0) if faces is None else faces
    body = "".join(f if isinstance(f, str) else polygon(f) for f in faces)
    return (f'<core:cityObjectMember><bldg:Building gml:id="{bid}">{extra}<bldg:lod1Solid><gml:Solid><gml:exterior>'
            f'<gml:CompositeSurface>\n{body}</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod1Solid>'
            f'</bldg:Building></core:cityObjectMember>\n')


def city(members, srs=SRS, prolog="", ns=NS):
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n{prolog}<core:CityModel {ns}>\n'
            f'<gml:boundedBy><gml:Envelope srsName="{srs}" srsDimension="3">'
            f'<gml:lowerCorner>400000 5860000 40</gml:lowerCorner><gml:upperCorner>400100 5860100 48</gml:upperCorner>'
            f'</gml:Envelope></gml:boundedBy>\n{"".join(members)}</core:CityModel>\n')


GOOD = building("GOOD_1", 400000, 5860000)
GOOD2 = building("GOOD_2", 400030, 5860000)


def write(name, data):
    p = HERE / name
    p.write_bytes(data if isinstance(data, bytes) else data.encode())


def main():
    random.seed(8)
    write("empty_file.gml", b"")
    write("binary_garbage.gml", bytes(random.randrange(256) for _ in range(4096)))
    whole = city([GOOD, GOOD2])
    write("truncated_in_prolog.gml", whole[:30])
    cut = whole.index('gml:id="GOOD_2"') + 400
    write("truncated_in_second_building.gml", whole[:cut])
    write("truncated_before_end_tag.gml", whole[:whole.rindex("</core:CityModel>")])
    # Namespaces: CityGML's URI misspelt (nothing is CityGML); GML's URI wrong (buildings without polygons).
    write("wrong_citygml_namespace.gml", city([GOOD], ns=NS.replace("http://www.opengis.net/citygml/",
                                                                     "http://www.opengis.net/cityGML/")))
    write("wrong_gml_namespace.gml", city([GOOD], ns=NS.replace('xmlns:gml="http://www.opengis.net/gml"',
                                                                'xmlns:gml="http://www.opengis.net/gml/9.9"')))
    write("unknown_srsname.gml", city([GOOD], srs="EPSG:999999"))
    write("malformed_srsname.gml", city([GOOD], srs="urn:ogc:def:crs:EPSG::not-a-code"))
    write("crs_4326_on_metres.gml", city([GOOD], srs="EPSG:4326"))
    xlink_missing = ('<core:cityObjectMember><bldg:Building gml:id="XLINK_MISSING"><bldg:lod2Solid><gml:Solid>'
                     '<gml:exterior><gml:CompositeSurface><gml:surfaceMember xlink:href="#NO_SUCH_POLYGON"/>'
                     '<gml:surfaceMember xlink:href="#NOR_THIS_ONE"/></gml:CompositeSurface></gml:exterior>'
                     '</gml:Solid></bldg:lod2Solid></bldg:Building></core:cityObjectMember>\n')
    write("xlink_target_missing.gml", city([GOOD, xlink_missing]))
    faces = box_faces(400030, 5860000)
    two_points = polygon(None, poslist="400030 5860000 40 400040 5860000 40 400030 5860000 40")
    write("ring_too_few_points.gml", city([GOOD, building("RING_TWO_POINTS", 0, 0, faces=[two_points])]))
    write("ring_too_few_points_one_face.gml",
          city([GOOD, building("ONE_BAD_FACE", 0, 0, faces=faces[:1] + [two_points] + faces[1:])]))
    for tag, value in (("nan", "NaN"), ("inf", "INF"), ("1e300", "1e300"), ("1e400", "1e400")):
        bad = polygon(None, poslist=ring(faces[0]).replace("400030.0", value, 1))
        write(f"coordinate_{tag}.gml", city([GOOD, building(f"COORD_{tag.upper()}", 0, 0, faces=[bad] + faces[1:])]))
    write("duplicate_gml_ids.gml", city([GOOD, building("GOOD_1", 400030, 5860000)]))
    no_geom = ('<core:cityObjectMember><bldg:Building gml:id="NO_GEOMETRY"><bldg:measuredHeight uom="m">8'
               '</bldg:measuredHeight></bldg:Building></core:cityObjectMember>\n')
    write("building_without_geometry.gml", city([GOOD, no_geom]))
    walls_only = building("WALLS_ONE_PLANE", 0, 0, faces=[faces[2], faces[4]])
    write("building_unusable_geometry.gml", city([GOOD, walls_only]))
    write("all_buildings_unusable.gml", city([no_geom]))
    deep = "<core:cityObjectMember>" + "<bldg:Building>" * 2000
    write("deeply_nested.gml", city([GOOD])[:-len("</core:CityModel>\n")] + deep)
    lol = ('<!DOCTYPE lolz [\n <!ENTITY lol "lol">\n' +
           "".join(f' <!ENTITY lol{i} "{("&lol" + (str(i - 1) if i > 1 else "") + ";") * 10}">\n'
                   for i in range(1, 10)) + ']>\n')
    write("entity_expansion.gml", city([GOOD], prolog=lol).replace("GOOD_1", "&lol9;", 1))
    xxe = '<!DOCTYPE core:CityModel [ <!ENTITY xxe SYSTEM "file:///etc/passwd"> ]>\n'
    write("external_entity.gml", city([GOOD], prolog=xxe).replace("GOOD_1", "&xxe;", 1))
    xxe_dtd = '<!DOCTYPE core:CityModel SYSTEM "file:///etc/passwd">\n'
    write("external_dtd.gml", city([GOOD], prolog=xxe_dtd))
    claim = building("DIMENSION_CLAIM", 0, 0, faces=[polygon(None, poslist=ring(f)) for f in faces])
    claim = claim.replace('srsDimension="3"', 'srsDimension="1000000000" count="2147483647"')
    write("coordinate_count_claim.gml", city([GOOD, claim]))
    write("srs_dimension_claim_on_envelope.gml",
          city([GOOD]).replace('srsDimension="3"', 'srsDimension="4294967296"', 1))



# --- KML / KMZ + COLLADA, glTF (their readers landed with c6de234) ----------------------------------
def collada(bad_index=False):
    pos = "0 0 0 10 0 0 10 8 0 0 8 0 0 0 6 10 0 6 10 8 6 0 8 6"
    tris = [0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7]
    if bad_index:
        tris[5] = 99  # one index past the 8 positions
        tris[7] = -3
    return f'''<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit meter="1" name="meter"/><up_axis>Z_UP</up_axis></asset>
<library_geometries><geometry id="box"><mesh>
<source id="box-pos"><float_array id="box-pos-array" count="24">{pos}</float_array>
<technique_common><accessor source="#box-pos-array" count="8" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="box-vtx"><input semantic="POSITION" source="#box-pos"/></vertices>
<triangles count="12"><input semantic="VERTEX" source="#box-vtx" offset="0"/><p>{" ".join(map(str, tris))}</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#box"/></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
'''


def kml(placemarks):
    pms = "".join(f'''<Placemark id="{pid}"><Model><Location><longitude>{127.17 + 0.001 * i}</longitude>
<latitude>37.62</latitude><altitude>0</altitude></Location><Link><href>{href}</href></Link></Model></Placemark>
''' for i, (pid, href) in enumerate(placemarks))
    return f'<?xml version="1.0" encoding="UTF-8"?>\n<kml xmlns="http://www.opengis.net/kml/2.2"><Document>\n{pms}</Document></kml>\n'


def gltf_box(bad_accessor=False):
    """Two nodes with a box each, placed by CESIUM_RTC; the second's index accessor runs past its buffer."""
    import base64, json, math, struct
    lon, lat = math.radians(127.17), math.radians(37.62)
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
    center = [n * math.cos(lat) * math.cos(lon), n * math.cos(lat) * math.sin(lon), n * (1 - e2) * math.sin(lat)]
    # A 10 x 8 x 6 m box in the local east-north-up frame, written as ECEF offsets from the centre
    # (CESIUM_RTC), in glTF's y-up axes: the reader turns (x, y, z) into (x, -z, y).
    east = (-math.sin(lon), math.cos(lon), 0.0)
    north = (-math.sin(lat) * math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat))
    up = (math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat))
    enu = [(0, 0, 0), (10, 0, 0), (10, 8, 0), (0, 8, 0), (0, 0, 6), (10, 0, 6), (10, 8, 6), (0, 8, 6)]
    p = []
    for e, nn, u in enu:
        o = [e * east[k] + nn * north[k] + u * up[k] for k in range(3)]
        p.append((o[0], o[2], -o[1]))
    idx = [0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1, 1, 5, 6, 1, 6, 2, 2, 6, 7, 2, 7, 3, 3, 7, 4, 3, 4, 0]
    blob = b"".join(struct.pack("<3f", *v) for v in p) + struct.pack(f"<{len(idx)}H", *idx)
    doc = {
        "asset": {"version": "2.0"}, "extensionsUsed": ["CESIUM_RTC"],
        "extensions": {"CESIUM_RTC": {"center": center}},
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 72}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [min(v[k] for v in p) for k in range(3)],
             "max": [max(v[k] for v in p) for k in range(3)]},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5123, "count": 36000000 if bad_accessor else 36, "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]},
                   {"primitives": [{"attributes": {"POSITION": 0}, "indices": 2}]}],
        "nodes": [{"name": "GOOD_BOX", "mesh": 0}, {"name": "BAD_ACCESSOR", "mesh": 1, "translation": [30, 0, 0]}],
        "scenes": [{"nodes": [0, 1]}], "scene": 0}
    return json.dumps(doc)


def main_models():
    write("kml_models/good_box.dae", collada())
    write("kml_models/broken_indices.dae", collada(bad_index=True))
    write("kml_link_to_missing_dae.kml", kml([("GOOD_PM", "kml_models/good_box.dae"), ("MISSING_PM", "kml_models/no_such_model.dae")]))
    write("kml_dae_with_broken_indices.kml", kml([("GOOD_PM", "kml_models/good_box.dae"), ("BROKEN_PM", "kml_models/broken_indices.dae")]))
    write("kmz_not_a_zip.kmz", "PK? no, this is plain text pretending to be a KMZ archive\n" * 20)
    write("gltf_accessor_out_of_range.gltf", gltf_box(bad_accessor=True))


if __name__ == "__main__":
    (HERE / "kml_models").mkdir(exist_ok=True)
    main()
    main_models()

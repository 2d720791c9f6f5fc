#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Makes the 3D Tiles test data in this folder from a CityGML sample (see SOURCE.txt). A test tool, not part of
groundplan: it reads the CityGML with Python's ElementTree (not with groundplan's reader), triangulates each
polygon with mapbox_earcut, places it on the Earth with pyproj (EPSG:25832 + height -> EPSG:4978), and writes
3D Tiles 1.0 (b3dm + tileset.json) itself; the 1.1, Draco and meshopt copies are made from those by CesiumGS's
3d-tiles-tools (upgrade), gltf-pipeline (-d) and gltfpack (-c), installed from npm into a temporary folder.

Usage (from the repository root): /usr/bin/python3 tests/data/3dtiles/make_tilesets.py
Needs Debian's python3-numpy, python3-pyproj, python3-mapbox-earcut, npm."""
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import mapbox_earcut
import numpy as np
import pyproj

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
SOURCE = os.path.join(REPO, "..", "shared", "data", "citygml1-niedersachsen-lod1-4tiles", "LoD1_24065862_2_2021-01-25.gml")
NS = {"gml": "http://www.opengis.net/gml", "bldg": "http://www.opengis.net/citygml/building/1.0",
      "core": "http://www.opengis.net/citygml/1.0"}
GML_ID = "{http://www.opengis.net/gml}id"


def buildings(path):
    """[(gml_id, [polygon: [ring: [(x, y, z)]]])] of every top-level Building, its BuildingParts' polygons included."""
    out = []
    root = ET.parse(path).getroot()
    for member in root.findall("core:cityObjectMember", NS):
        b = member.find("bldg:Building", NS)
        if b is None:
            continue
        polys = []
        for poly in b.iter("{http://www.opengis.net/gml}Polygon"):
            rings = []
            for ring in poly.iter("{http://www.opengis.net/gml}LinearRing"):
                pl = ring.find("gml:posList", NS)
                v = [float(t) for t in pl.text.split()]
                pts = [tuple(v[i:i + 3]) for i in range(0, len(v), 3)]
                if len(pts) > 1 and pts[0] == pts[-1]:
                    pts = pts[:-1]
                rings.append(pts)
            polys.append(rings)
        out.append((b.get(GML_ID), polys))
    return out


def triangulate(rings):
    """Triangles (index triples into the concatenated rings) of one planar polygon with holes."""
    pts = np.array([p for r in rings for p in r], dtype=np.float64)
    n = np.zeros(3)
    for r in rings[:1]:  # Newell normal of the outer ring
        for i in range(len(r)):
            a, b = np.array(r[i]), np.array(r[(i + 1) % len(r)])
            n += np.cross(a - pts[0], b - pts[0])
    drop = int(np.argmax(np.abs(n)))
    keep = [k for k in range(3) if k != drop]
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    tri = mapbox_earcut.triangulate_float64((pts[:, keep] - pts[0, keep]), ends)
    return pts, tri.reshape(-1, 3)


TO_ECEF = pyproj.Transformer.from_crs(pyproj.CRS("EPSG:25832").to_3d(), "EPSG:4978", always_xy=True)
TO_GEO = pyproj.Transformer.from_crs("EPSG:4978", "EPSG:4979", always_xy=True)


def enu_frame(centre):
    lon, lat, _ = TO_GEO.transform(*centre)
    lo, la = math.radians(lon), math.radians(lat)
    e = np.array([-math.sin(lo), math.cos(lo), 0.0])
    n = np.array([-math.sin(la) * math.cos(lo), -math.sin(la) * math.sin(lo), math.cos(la)])
    u = np.array([math.cos(la) * math.cos(lo), math.cos(la) * math.sin(lo), math.sin(la)])
    return np.column_stack([e, n, u])


def column_major(r, t):
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = t
    return [float(v) for v in m.T.reshape(-1)]


def mesh_of(blds, to_local):
    """Positions (float32, glTF y-up), batch ids and indices of the buildings' triangles."""
    pos, bid, idx = [], [], []
    for b, (_, polys) in enumerate(blds):
        for rings in polys:
            if sum(len(r) for r in rings) < 3:
                continue
            pts, tri = triangulate(rings)
            ecef = np.array(TO_ECEF.transform(pts[:, 0], pts[:, 1], pts[:, 2])).T
            local = to_local(ecef)  # z-up
            base = len(pos)
            for p in local:
                pos.append((p[0], p[2], -p[1]))  # z-up -> glTF y-up: (x, y, z) -> (x, z, -y)
                bid.append(b)
            idx.extend(int(base + i) for i in tri.reshape(-1))
    return np.array(pos, dtype=np.float32), np.array(bid, dtype=np.uint16), np.array(idx, dtype=np.uint32)


def pad(b, n, fill=b"\0"):
    return b + fill * ((-len(b)) % n)


def glb(json_obj, bin_bytes):
    j = pad(json.dumps(json_obj, separators=(",", ":")).encode(), 4, b" ")
    b = pad(bin_bytes, 4)
    body = struct.pack("<I4s", len(j), b"JSON") + j + struct.pack("<I4s", len(b), b"BIN\0") + b
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def batched_glb(pos, bid, idx):
    """One mesh, one primitive with POSITION, _BATCHID (3D Tiles 1.0) and indices."""
    p, b, i = pos.tobytes(), bid.tobytes(), idx.tobytes()
    b_off = len(p)
    i_off = b_off + len(pad(b, 4))
    bin_bytes = p + pad(b, 4) + i
    g = {"asset": {"version": "2.0", "generator": "groundplan tests/data/3dtiles/make_tilesets.py"},
         "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
         "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "_BATCHID": 1}, "indices": 2}]}],
         "accessors": [
             {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
              "min": [float(v) for v in pos.min(0)], "max": [float(v) for v in pos.max(0)]},
             {"bufferView": 1, "componentType": 5123, "count": len(bid), "type": "SCALAR"},
             {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"}],
         "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(p), "target": 34962},
                         {"buffer": 0, "byteOffset": b_off, "byteLength": len(b), "target": 34962},
                         {"buffer": 0, "byteOffset": i_off, "byteLength": len(i), "target": 34963}],
         "buffers": [{"byteLength": len(bin_bytes)}]}
    return glb(g, bin_bytes)


def nodes_glb(blds, to_local):
    """One node (named by the gml:id) and mesh per building, no feature ids."""
    bin_bytes, accessors, views, meshes, nodes = b"", [], [], [], []
    for k, b in enumerate(blds):
        pos, _, idx = mesh_of([b], to_local)
        for arr, comp, typ, target in ((pos, 5126, "VEC3", 34962), (idx, 5125, "SCALAR", 34963)):
            views.append({"buffer": 0, "byteOffset": len(bin_bytes), "byteLength": arr.nbytes, "target": target})
            acc = {"bufferView": len(views) - 1, "componentType": comp, "count": len(arr), "type": typ}
            if typ == "VEC3":
                acc["min"], acc["max"] = [float(v) for v in arr.min(0)], [float(v) for v in arr.max(0)]
            accessors.append(acc)
            bin_bytes = pad(bin_bytes + arr.tobytes(), 4)
        meshes.append({"primitives": [{"attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1}]})
        nodes.append({"mesh": k, "name": b[0]})
    g = {"asset": {"version": "2.0", "generator": "groundplan tests/data/3dtiles/make_tilesets.py"},
         "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
         "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(bin_bytes)}]}
    return glb(g, bin_bytes)


def b3dm(glb_bytes, names, rtc=None):
    ft = {"BATCH_LENGTH": len(names)}
    if rtc is not None:
        ft["RTC_CENTER"] = [float(v) for v in rtc]
    # each section padded with spaces so that the next starts on an 8-byte boundary of the file (header: 28 bytes)
    ftj = json.dumps(ft).encode()
    ftj += b" " * ((-(28 + len(ftj))) % 8)
    btj = json.dumps({"gml_id": names}).encode()
    btj += b" " * ((-(28 + len(ftj) + len(btj))) % 8)
    body = ftj + btj + pad(glb_bytes, 8)
    return struct.pack("<4s6I", b"b3dm", 1, 28 + len(body), len(ftj), 0, len(btj), 0) + body


def i3dm(glb_bytes, rtc, offsets, names):
    """Instances of one model at RTC_CENTER + offsets (float32), oriented east-north-up, BATCH_ID i, batch table gml_id."""
    n = len(offsets)
    pos = np.array(offsets, dtype=np.float32).tobytes()
    bid = np.arange(n, dtype=np.uint16).tobytes()
    ftb = pad(pos, 4) + bid
    ftb = pad(ftb, 8)
    ft = {"INSTANCES_LENGTH": n, "RTC_CENTER": [float(v) for v in rtc], "EAST_NORTH_UP": True,
          "POSITION": {"byteOffset": 0}, "BATCH_ID": {"byteOffset": len(pad(pos, 4)), "componentType": "UNSIGNED_SHORT"}}
    ftj = json.dumps(ft).encode()
    ftj += b" " * ((-(32 + len(ftj))) % 8)
    btj = json.dumps({"gml_id": names}).encode()
    btj += b" " * ((-(32 + len(ftj) + len(ftb) + len(btj))) % 8)
    body = ftj + ftb + btj + pad(glb_bytes, 8)
    return struct.pack("<4s7I", b"i3dm", 1, 32 + len(body), len(ftj), len(ftb), len(btj), 0, 1) + body


def tile(uri, error, transform=None, children=None, refine=None):
    t = {"boundingVolume": {"sphere": [0, 0, 0, 1e4]}, "geometricError": error}
    if transform is not None:
        t["transform"] = transform
    if refine:
        t["refine"] = refine
    if uri:
        t["content"] = {"uri": uri}
    if children:
        t["children"] = children
    return t


def tileset(root, version="1.0"):
    return {"asset": {"version": version}, "geometricError": 1000, "root": root}


def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb" if isinstance(data, bytes) else "w") as f:
        f.write(data if isinstance(data, bytes) else json.dumps(data, indent=1) + "\n")


def npm_tools():
    """The npm tools, installed into a temporary folder (or one named by GROUNDPLAN_NPM_PREFIX, kept)."""
    prefix = os.environ.get("GROUNDPLAN_NPM_PREFIX") or tempfile.mkdtemp(prefix="groundplan-3dtiles-npm-")
    subprocess.run(["npm", "install", "--silent", "--prefix", prefix, "3d-tiles-tools@0.5.4", "gltf-pipeline@4.3.1",
                    "gltfpack@1.3.0"], check=True)
    return prefix, os.path.join(prefix, "node_modules", ".bin")


def main():
    blds = buildings(SOURCE)
    # The centre: the ECEF point of the buildings' mean position; the tiles' local frame is east-north-up there.
    allpts = np.array([p for _, polys in blds for rings in polys for r in rings for p in r])
    c = np.array(TO_ECEF.transform(*allpts.mean(0)))
    r = enu_frame(c)
    to_enu = lambda ecef: (ecef - c) @ r
    # West and east halves by the buildings' mean x.
    mid = float(np.median([np.mean([p[0] for rings in polys for ring in rings for p in ring]) for _, polys in blds]))
    west = [b for b in blds if np.mean([p[0] for rings in b[1] for ring in rings for p in ring]) < mid]
    east = [b for b in blds if b not in west]
    names = lambda bs: [b[0] for b in bs]
    out = HERE
    for sub in ("b3dm", "glb", "draco", "meshopt", "levels", "i3dm", "i3dm_glb", "implicit"):
        shutil.rmtree(os.path.join(out, sub), ignore_errors=True)

    # 1.0: root translated to the centre; the west tile turned to ENU there (transforms composed); the east tile
    # undoing the root's translation and placed by its b3dm's RTC_CENTER (ECEF offsets, no turn).
    c_east = np.array(TO_ECEF.transform(*np.array([p for _, ps in east for rs in ps for rg in rs for p in rg]).mean(0)))
    write(os.path.join(out, "b3dm", "west.b3dm"), b3dm(batched_glb(*mesh_of(west, to_enu)), names(west)))
    write(os.path.join(out, "b3dm", "east.b3dm"),
          b3dm(batched_glb(*mesh_of(east, lambda e: e - c_east)), names(east), rtc=c_east))
    root = tile(None, 500, column_major(np.eye(3), c), refine="REPLACE", children=[
        tile("west.b3dm", 0, column_major(r, [0, 0, 0])),
        tile("east.b3dm", 0, column_major(np.eye(3), -c))])
    write(os.path.join(out, "b3dm", "tileset.json"), tileset(root))
    # An external tileset: the same tree through a tile whose content is the tileset above.
    write(os.path.join(out, "b3dm", "outer.json"), tileset(tile("tileset.json", 1000)))

    # Levels of detail: the whole city in the parent (all.b3dm), the halves in the children.
    lv = os.path.join(out, "levels")
    write(os.path.join(lv, "all.b3dm"), b3dm(batched_glb(*mesh_of(blds, to_enu)), names(blds)))
    write(os.path.join(lv, "west.b3dm"), b3dm(batched_glb(*mesh_of(west, to_enu)), names(west)))
    write(os.path.join(lv, "east.b3dm"), b3dm(batched_glb(*mesh_of(east, to_enu)), names(east)))
    enu = column_major(r, c)
    write(os.path.join(lv, "replace.json"),
          tileset(tile("all.b3dm", 500, enu, refine="REPLACE", children=[tile("west.b3dm", 0), tile("east.b3dm", 0)])))
    write(os.path.join(lv, "add.json"), tileset(tile("west.b3dm", 500, enu, refine="ADD", children=[tile("east.b3dm", 0)])))

    # Implicit tiling (3D Tiles 1.1, QUADTREE, 2 levels in one binary subtree): level 0 all buildings (REPLACE),
    # level 1 three quadrants around the centre (a building by its mean point), content/{level}/{x}/{y}.b3dm.
    im = os.path.join(out, "implicit")
    write(os.path.join(im, "content", "0", "0", "0.b3dm"), b3dm(batched_glb(*mesh_of(blds, to_enu)), names(blds)))
    quads = {}
    for b in blds:
        m = to_enu(np.array(TO_ECEF.transform(*np.array([p for rs in b[1] for rg in rs for p in rg]).mean(0))))
        quads.setdefault((int(m[0] >= 0), int(m[1] >= 0)), []).append(b)
    # Tile (x 0, y 1) is not available: its buildings go with tile (0, 0), so that availability is not symmetric in
    # x and y (a reader that swapped them would ask for content/1/0/1.b3dm, which is not there).
    quads[(0, 0)] = quads.get((0, 0), []) + quads.pop((0, 1), [])
    bits = 1  # the root
    for (x, y), bs in sorted(quads.items()):
        write(os.path.join(im, "content", "1", str(x), f"{y}.b3dm"), b3dm(batched_glb(*mesh_of(bs, to_enu)), names(bs)))
        bits |= 1 << (1 + (x | (y << 1)))  # level 1 starts at bit 1, tiles in Morton order
    avail = bytes([bits])
    sj = json.dumps({"buffers": [{"byteLength": 8}], "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 1}],
                     "tileAvailability": {"bitstream": 0}, "contentAvailability": [{"bitstream": 0}],
                     "childSubtreeAvailability": {"constant": 0}}).encode()
    sj += b" " * ((-len(sj)) % 8)
    sb = pad(avail, 8)
    write(os.path.join(im, "subtrees", "0", "0", "0.subtree"), struct.pack("<4sIQQ", b"subt", 1, len(sj), len(sb)) + sj + sb)
    write(os.path.join(im, "tileset.json"), {
        "asset": {"version": "1.1"}, "geometricError": 1000,
        "root": {"boundingVolume": {"sphere": [0, 0, 0, 1e4]}, "geometricError": 500, "refine": "REPLACE",
                 "transform": enu, "content": {"uri": "content/{level}/{x}/{y}.b3dm"},
                 "implicitTiling": {"subdivisionScheme": "QUADTREE", "subtreeLevels": 2, "availableLevels": 2,
                                    "subtrees": {"uri": "subtrees/{level}/{x}/{y}.subtree"}}}})

    # i3dm: one building as a model in east-north-up at its own centre, instanced there and 100 m east.
    b0 = west[0]
    b0pts = np.array([p for rings in b0[1] for r in rings for p in r])
    cb = np.array(TO_ECEF.transform(*b0pts.mean(0)))
    rb = enu_frame(cb)
    model = batched_glb(*mesh_of([b0], lambda e: (e - cb) @ rb))
    east100 = 100.0 * rb[:, 0]
    write(os.path.join(out, "i3dm", "instances.i3dm"), i3dm(model, cb, [[0, 0, 0], east100], [b0[0], b0[0] + "-east"]))
    write(os.path.join(out, "i3dm", "tileset.json"), tileset(tile("instances.i3dm", 0)))
    to25832 = pyproj.Transformer.from_crs("EPSG:4978", pyproj.CRS("EPSG:25832").to_3d(), always_xy=True)
    a, b = np.array(to25832.transform(*cb)), np.array(to25832.transform(*(cb + east100)))
    i3dm_check = {"building": b0[0], "copy": b0[0] + "-east", "offset_epsg25832": [float(v) for v in b - a]}

    prefix, bin_dir = npm_tools()
    try:
        # 1.1: the b3dm tileset upgraded by 3d-tiles-tools (b3dm -> glb with EXT_mesh_features / EXT_structural_metadata).
        subprocess.run([os.path.join(bin_dir, "3d-tiles-tools"), "upgrade", "-i", os.path.join(out, "b3dm", "tileset.json"),
                        "-o", os.path.join(out, "glb"), "--targetVersion", "1.1", "-f"], check=True)
        # The i3dm tileset upgraded too: glb with EXT_mesh_gpu_instancing and EXT_instance_features.
        subprocess.run([os.path.join(bin_dir, "3d-tiles-tools"), "upgrade", "-i", os.path.join(out, "i3dm", "tileset.json"),
                        "-o", os.path.join(out, "i3dm_glb"), "--targetVersion", "1.1", "-f"], check=True)
        # Draco: every glb of the 1.1 tileset compressed by gltf-pipeline, positions quantized to 24 bits (0.1 mm
        # steps over a tile: its default, 11 bits, moves walls by decimetres).
        shutil.copytree(os.path.join(out, "glb"), os.path.join(out, "draco"))
        for f in sorted(os.listdir(os.path.join(out, "draco"))):
            if f.endswith(".glb"):
                p = os.path.join(out, "draco", f)
                subprocess.run([os.path.join(bin_dir, "gltf-pipeline"), "-i", p, "-o", p, "-d",
                                "--draco.quantizePositionBits", "24"], check=True)
        # meshopt + quantization: one node per building (no feature ids), packed by gltfpack keeping the named nodes.
        mo = os.path.join(out, "meshopt")
        os.makedirs(mo)
        plain = os.path.join(tempfile.mkdtemp(), "nodes.glb")
        write(plain, nodes_glb(blds, to_enu))
        # nodes.glb: EXT_meshopt_compression of the float positions as they are (-noq: lossless); quantized.glb:
        # 16-bit normalized positions (KHR_mesh_quantization, dequantized by node transforms); khr.glb:
        # KHR_meshopt_compression, lossless.
        for name, flags in (("nodes", ["-noq"]), ("quantized", ["-vp", "16", "-vpn"]), ("khr", ["-noq", "-ce", "khr"])):
            subprocess.run([os.path.join(bin_dir, "gltfpack"), "-i", plain, "-o", os.path.join(mo, name + ".glb"),
                            "-c", "-kn"] + flags, check=True)
            write(os.path.join(mo, name + ".json"), tileset(tile(name + ".glb", 0, enu), "1.1"))
    finally:
        if not os.environ.get("GROUNDPLAN_NPM_PREFIX"):
            shutil.rmtree(prefix, ignore_errors=True)

    # For the georeferencing test: a few vertices as stored (float32, y-up, west tile) with pyproj's EPSG:25832
    # position of each, computed here from the stored numbers: ENU (double) -> ECEF -> EPSG:25832.
    pos, _, _ = mesh_of(west[:1], to_enu)
    back = pyproj.Transformer.from_crs("EPSG:4978", pyproj.CRS("EPSG:25832").to_3d(), always_xy=True)
    checks = []
    for p in pos[:: max(1, len(pos) // 4)][:4]:
        local = np.array([float(p[0]), -float(p[2]), float(p[1])])  # y-up -> z-up
        e = c + r @ local
        x, y, z = back.transform(*e)
        checks.append({"stored_gltf_y_up": [float(v) for v in p], "epsg25832": [x, y, z]})
    write(os.path.join(out, "georef_check.json"), {"building": west[0][0], "tile": "b3dm/west.b3dm", "vertices": checks,
                                                   "i3dm": i3dm_check})
    print(f"{len(blds)} buildings: {len(west)} west, {len(east)} east", file=sys.stderr)


if __name__ == "__main__":
    main()

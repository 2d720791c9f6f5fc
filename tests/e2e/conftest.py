# SPDX-License-Identifier: MIT
"""Fixtures for the end-to-end tests: the built CLI and plugin, sample paths, GDAL with our driver."""
import json
import os
import pathlib
import subprocess

import pytest
from osgeo import gdal, ogr

gdal.UseExceptions()

SOURCE_DIR = pathlib.Path(os.environ.get("GROUNDPLAN_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
BIN = os.environ.get("GROUNDPLAN_BIN", str(SOURCE_DIR / "build" / "bin" / "groundplan"))
PLUGIN_DIR = os.environ.get("GDAL_DRIVER_PATH", str(SOURCE_DIR / "build" / "gdalplugins"))
SAMPLES = SOURCE_DIR / "sample_data"
# Real third-party city models, one folder per dataset named as in ../shared/data (tests/data/README.md):
# SHARED_DATA holds those that may be redistributed (in the repository, each folder with its SOURCE.txt);
# THIRDPARTY_DATA the others, outside the repository: GROUNDPLAN_SHARED_DATA_DIR, else ../shared/data beside the
# source tree (or the folder cmake was given, GROUNDPLAN_SHARED_DATA_CONFIGURED under ctest). Tests that need them
# are marked thirdparty_data (ctest label thirdparty-data) and skip without them.
SHARED_DATA = SOURCE_DIR / "tests" / "data"
THIRDPARTY_DATA = pathlib.Path(os.environ.get("GROUNDPLAN_SHARED_DATA_DIR")
                               or os.environ.get("GROUNDPLAN_SHARED_DATA_CONFIGURED")
                               or SOURCE_DIR.parent / "shared" / "data")
THIRDPARTY_MISSING = (f"needs the third-party samples folder {THIRDPARTY_DATA} (not redistributable, not in the "
                      "repository; set GROUNDPLAN_SHARED_DATA_DIR to a copy of the samples)")
thirdparty_data = pytest.mark.thirdparty_data

PLATEAU = SAMPLES / "plateau-niiza" / "53395404_bldg_6697_op.gml"
PLATEAU_SMALL = SAMPLES / "plateau-niiza" / "53392547_bldg_6697_op2.gml"
LORUP = SAMPLES / "niedersachsen-lorup" / "LoD1_24065862_2_2021-01-25.gml"
TUM = SAMPLES / "tum-main-entrance" / "TUM-Main-Entrance.gml"
BERLIN = THIRDPARTY_DATA / "citygml1-berlin-lod2-libcitygml" / "berlin_open_data_sample_data.citygml"


def real_sample_files(suffixes, thirdparty=False):
    """Every file with one of `suffixes` of the real samples in the repository (sample_data/, tests/data/), or of
    the third-party folder less what tests/data/ holds too; each file once (links followed), sorted."""
    if thirdparty:
        roots = [THIRDPARTY_DATA] if THIRDPARTY_DATA.is_dir() else []
    else:
        roots = [SAMPLES, SHARED_DATA]
    seen, out = set(), []
    for root in roots:
        for p in sorted(root.rglob("*")):
            if p.suffix.lower() not in suffixes or not p.is_file():
                continue
            if thirdparty and (SHARED_DATA / p.relative_to(root)).exists():
                continue
            if p.resolve() not in seen:
                seen.add(p.resolve())
                out.append(p)
    return sorted(out)


def pytest_configure(config):
    config.addinivalue_line("markers", "thirdparty_data: needs real samples that may not be redistributed "
                                       "(THIRDPARTY_DATA); skipped where they are absent")


def pytest_sessionstart(session):
    """The ctest of the thirdparty-data label (-m thirdparty_data) where the folder is absent: one line, and the exit
    code ctest counts as a skip (SKIP_RETURN_CODE 77), not a pass."""
    if session.config.getoption("markexpr") == "thirdparty_data" and not THIRDPARTY_DATA.is_dir():
        print(f"SKIPPED: {THIRDPARTY_MISSING}", flush=True)
        os._exit(77)  # before anything is set up; pytest.exit would say it twice


def pytest_runtest_setup(item):
    if item.get_closest_marker("thirdparty_data") is not None and not THIRDPARTY_DATA.is_dir():
        pytest.skip(THIRDPARTY_MISSING)


def gdal_env():
    env = dict(os.environ)
    env["GDAL_DRIVER_PATH"] = PLUGIN_DIR
    return env


def run(args, check=True):
    """Runs a command; returns CompletedProcess with text output. Fails the test with the output on error."""
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True, env=gdal_env(), timeout=600)
    if check and p.returncode != 0:
        pytest.fail(f"{' '.join(map(str, args))} exited {p.returncode}\nstdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p


@pytest.fixture(scope="session", autouse=True)
def register_plugin():
    """Loads our plugin into this Python process's GDAL, as QGIS or a pipeline script would."""
    gdal.SetConfigOption("GDAL_DRIVER_PATH", PLUGIN_DIR)
    gdal.AllRegister()
    assert gdal.GetDriverByName("GroundPlan") is not None, f"plugin not found in {PLUGIN_DIR}"


def layer_rows(path, layer_name):
    """[(fields dict, geometry WKB)] of a layer, ordered by FID."""
    ds = ogr.Open(str(path))
    assert ds is not None, path
    lyr = ds.GetLayerByName(layer_name)
    assert lyr is not None, f"{path} has no layer {layer_name}"
    rows = []
    for f in lyr:
        g = f.GetGeometryRef()
        rows.append((f.items(), g.ExportToIsoWkb() if g else None))
    return rows


def square(x, y, s):
    return [[x, y], [x + s, y], [x + s, y + s], [x, y + s], [x, y]]


@pytest.fixture(scope="module")
def parts(tmp_path_factory):
    """About 44,000 building parts in EPSG:25832 (a grid of squares, some overlapping a neighbour, some with a
    courtyard) and a few degenerate ones (problems): about 35,000 plans (pairs of cells joined), enough for four writers."""
    features = []
    for i in range(220):
        for j in range(180):
            x, y = 400000.0 + 10 * i, 5800000.0 + 10 * j
            rings = [square(x, y, 8.0)]
            if (i * j) % 13 == 5:
                rings.append(square(x + 3, y + 3, 2.0)[::-1])
            features.append({"type": "Feature", "properties": {"id": f"b{i}_{j}"},
                             "geometry": {"type": "Polygon", "coordinates": rings}})
            if (i + j) % 9 == 0:  # a second part overlapping this one and the next cell's
                features.append({"type": "Feature", "properties": {"id": f"p{i}_{j}"},
                                 "geometry": {"type": "Polygon", "coordinates": [square(x + 5, y + 2, 6.5)]}})
    for k in range(5):  # no area: each a problem, nothing written for it
        x = 399000.0 + 10 * k
        features.append({"type": "Feature", "properties": {"id": f"flat{k}"},
                         "geometry": {"type": "Polygon", "coordinates": [[[x, 0], [x + 1, 0], [x + 2, 0], [x, 0]]]}})
    path = tmp_path_factory.mktemp("writers") / "parts.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection",
                                "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::25832"}},
                                "features": features}))
    return path


def _box_faces(x, y, w, d, z0, z1):
    """The six faces of an axis-aligned box as posList strings (outward rings)."""
    a, b, c, e = (x, y), (x + w, y), (x + w, y + d), (x, y + d)

    def ring(pts):
        pts = pts + [pts[0]]
        return " ".join(f"{px} {py} {pz}" for px, py, pz in pts)

    bottom = [(*a, z0), (*e, z0), (*c, z0), (*b, z0)]
    top = [(*a, z1), (*b, z1), (*c, z1), (*e, z1)]
    walls = [[(*p, z0), (*q, z0), (*q, z1), (*p, z1)] for p, q in ((a, b), (b, c), (c, e), (e, a))]
    return [ring(f) for f in [bottom, top] + walls]


def _solid(boxes):
    faces = "".join(f"<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">"
                    f"{f}</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>"
                    for box in boxes for f in _box_faces(*box))
    return (f"<bldg:lod1Solid><gml:Solid><gml:exterior><gml:CompositeSurface>{faces}</gml:CompositeSurface>"
            f"</gml:exterior></gml:Solid></bldg:lod1Solid>")


def write_citygml(path, buildings, srs_name=None, envelope_on=None):
    """A CityGML 2.0 file of box buildings. `buildings`: [(id, boxes, parts)] where boxes are (x, y, w, d, z0, z1) of
    the Building's own solid and parts [(part id, boxes)] its BuildingParts'. `srs_name` goes on the CityModel's
    envelope, or, with envelope_on="LandUse" ("LandUse-after"), only on the envelope of a LandUse object written
    before (after) the buildings."""
    xs = [b[0] for _, boxes, parts in buildings for b in boxes + [bb for _, pb in parts for bb in pb]]
    ys = [b[1] for _, boxes, parts in buildings for b in boxes + [bb for _, pb in parts for bb in pb]]
    env = ""
    srs_attr = f' srsName="{srs_name}"' if srs_name else ""
    corners = (f"<gml:lowerCorner>{min(xs)} {min(ys)} 0</gml:lowerCorner>"
               f"<gml:upperCorner>{max(xs) + 100} {max(ys) + 100} 100</gml:upperCorner>")
    if envelope_on is None:
        env = f'<gml:boundedBy><gml:Envelope{srs_attr} srsDimension="3">{corners}</gml:Envelope></gml:boundedBy>'
    members = []
    if envelope_on in ("LandUse", "LandUse-after"):
        members.append(f'<core:cityObjectMember><luse:LandUse gml:id="LU1"><gml:boundedBy><gml:Envelope{srs_attr} '
                       f'srsDimension="3">{corners}</gml:Envelope></gml:boundedBy></luse:LandUse></core:cityObjectMember>')
    for bid, boxes, parts in buildings:
        body = _solid(boxes) if boxes else ""
        for pid, pboxes in parts:
            body += (f'<bldg:consistsOfBuildingPart><bldg:BuildingPart gml:id="{pid}">{_solid(pboxes)}'
                     f'</bldg:BuildingPart></bldg:consistsOfBuildingPart>')
        members.append(f'<core:cityObjectMember><bldg:Building gml:id="{bid}">{body}</bldg:Building></core:cityObjectMember>')
    if envelope_on == "LandUse-after":
        members.append(members.pop(0))
    pathlib.Path(path).write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" '
        'xmlns:bldg="http://www.opengis.net/citygml/building/2.0" '
        'xmlns:luse="http://www.opengis.net/citygml/landuse/2.0" xmlns:gml="http://www.opengis.net/gml">\n'
        + env + "\n".join(members) + "\n</core:CityModel>\n")
    return path

# SPDX-License-Identifier: MIT
"""Bad and hostile input (issue 8): every file of tests/corpus/bad through the real CLI with --stats.
Each file holds one defect; tests/corpus/bad/expected.json says what must come out: the exit code, the
problem codes, a fragment of the message, and the counts. Whatever the file, the run must end in
bounded time, never crash, name the file (and the building, when there is one) in its message, never
read outside its input, and lose no building silently."""
import json
import os
import pathlib

import pytest
from osgeo import ogr

from conftest import BIN, SOURCE_DIR, run

CORPUS = SOURCE_DIR / "tests" / "corpus" / "bad"
EXPECTED = json.loads((CORPUS / "expected.json").read_text())
INPUT_SUFFIXES = {".gml", ".xml", ".citygml", ".kml", ".kmz", ".gltf", ".glb"}  # a .dae belongs to a .kml


def _passwd_markers():
    """Lines of /etc/passwd that must never show up anywhere (XXE must not read it)."""
    try:
        lines = pathlib.Path("/etc/passwd").read_text().splitlines()
    except OSError:
        return []
    return [l for l in lines if l.count(":") >= 6][:3]


PASSWD = _passwd_markers()


def _problems(path):
    ds = ogr.Open(str(path))
    return [f.items() for f in ds.GetLayerByName("problems")]


def dropped_buildings(problems, footprints):
    """Buildings without a footprint, each named by a problem: one per georeference/footprint-stage
    problem, and one per building id (per file) that only read-stage problems name: a building given up
    by its reader. Read-stage defects of a building that still has a footprint do not count."""
    later = [p for p in problems if p["source_id"] and p["stage"] in ("georeference", "footprint")]
    kept = {(f["source_file"], f["source_id"]) for f in footprints} | {(p["file"], p["source_id"]) for p in later}
    given_up = {(p["file"], p["source_id"]) for p in problems if p["source_id"] and p["stage"] == "read"
                and p["code"] != "NOTE" and (p["file"], p["source_id"]) not in kept}
    return len(later) + len(given_up)


def check_nothing_lost(gpkg, counts):
    """buildings in = footprints + buildings given up (each with a problem naming it); every footprint
    is a member of a plan or has a union-stage problem. Returns the problems."""
    ds = ogr.Open(str(gpkg))
    problems = [f.items() for f in ds.GetLayerByName("problems")]
    footprints = [f.items() for f in ds.GetLayerByName("footprints")]
    assert len(footprints) == counts["footprints"]
    dropped = dropped_buildings(problems, footprints)
    assert counts["buildings"] == counts["footprints"] + dropped, (counts, problems)
    assert counts["dropped"] == dropped
    union_problems = {p["source_id"] for p in problems if p["stage"] == "union"}
    members = {(m["gp_id"], m["fp_id"]) for m in (f.items() for f in ds.GetLayerByName("plan_members"))}
    member_fps = {fp for _, fp in members}
    for f in footprints:
        in_plan = f["gp_id"] is not None and f["fp_id"] in member_fps
        assert in_plan or f["source_id"] in union_problems, f["source_id"]
    return problems


def test_every_corpus_file_has_an_expectation():
    files = {p.name for p in CORPUS.iterdir() if p.suffix.lower() in INPUT_SUFFIXES}
    assert files == set(EXPECTED), (files ^ set(EXPECTED))


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bad_file(tmp_path, name):
    want = EXPECTED[name]
    src = CORPUS / name
    out, stats = tmp_path / "out.gpkg", tmp_path / "stats.json"
    p = run([BIN, "--stats", stats, "-f", "GPKG", out, src, "ground_plans", "footprints", "problems",
             "plan_members"], check=False)
    assert p.returncode >= 0, f"killed by signal {-p.returncode}\n{p.stderr}"
    assert p.returncode == want["exit"], f"exit {p.returncode}\nstdout:\n{p.stdout}\nstderr:\n{p.stderr}"
    assert "Traceback" not in p.stderr and "terminate called" not in p.stderr
    # Every message names the file and says what is wrong.
    assert src.name in p.stderr, p.stderr
    assert want["message"] in p.stderr, p.stderr
    for b in want.get("building_ids", []):
        assert f"building {b}:" in p.stderr, p.stderr
    texts = [p.stdout, p.stderr]
    if want["exit"] == 0:
        counts = json.loads(stats.read_text())["counts"]
        for key in ("buildings", "footprints", "dropped"):
            assert counts[key] == want[key], (key, counts)
        problems = check_nothing_lost(out, counts)
        codes = {pr["code"] for pr in problems}
        assert set(want["codes"]) <= codes, codes
        for pr in problems:  # the file itself, or a model it links (a KML's .dae)
            assert pr["file"] == str(src) or pathlib.Path(pr["file"]).resolve().is_relative_to(CORPUS), pr
            texts.append(pr["reason"])
        texts.append(out.read_bytes().decode("latin-1"))
    elif "nothing usable" in p.stderr:
        # The problems layer asked for is still written, alone (no empty plans that would look like a result).
        ds = ogr.Open(str(out))
        assert [ds.GetLayer(i).GetName() for i in range(ds.GetLayerCount())] == ["problems"]
        problems = [f.items() for f in ds.GetLayer(0)]
        assert problems and set(want["codes"]) <= {pr["code"] for pr in problems}
        texts += [pr["reason"] for pr in problems]
    else:
        assert not out.exists() or want.get("output_written", False)
    for t in texts:
        for line in PASSWD:
            assert line not in t, "content of /etc/passwd in the output"


@pytest.mark.parametrize("tiles", ["off", "on"])
def test_problems_layer_is_written_when_nothing_is_usable(tmp_path, tiles):
    """1,000 buildings, none usable (a ring of two points each): the run fails, and the problems layer asked for
    holds every one of them; the message says where they are. Without the layer asked for, nothing is written."""
    members = "".join(
        f'<core:cityObjectMember><bldg:Building gml:id="BAD_{i}"><bldg:lod1Solid><gml:Solid><gml:exterior>'
        f'<gml:CompositeSurface><gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>'
        f'{i} 0 0 {i} 1 0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>'
        f'</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod1Solid></bldg:Building></core:cityObjectMember>\n'
        for i in range(1000))
    src = tmp_path / "bad.gml"
    src.write_text('<?xml version="1.0"?>\n<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" '
                   'xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml">'
                   '<gml:boundedBy><gml:Envelope srsName="EPSG:25832"><gml:lowerCorner>0 0 0</gml:lowerCorner>'
                   '<gml:upperCorner>1000 1 0</gml:upperCorner></gml:Envelope></gml:boundedBy>\n'
                   + members + "</core:CityModel>\n")
    out = tmp_path / "out.gpkg"
    p = run([BIN, "--tiles", tiles, "-f", "GPKG", out, src, "ground_plans", "problems"], check=False)
    assert p.returncode == 1, p.stderr
    assert "nothing usable: 1000 buildings read" in p.stderr and "only the 'problems' layer written" in p.stderr
    assert f"all are in the 'problems' layer of {out}" in p.stderr, p.stderr
    ds = ogr.Open(str(out))
    assert [ds.GetLayer(i).GetName() for i in range(ds.GetLayerCount())] == ["problems"]
    named = {f["source_id"] for f in ds.GetLayer(0) if f["code"] != "NOTE"}
    assert named == {f"BAD_{i}" for i in range(1000)}
    plans_only = tmp_path / "plans.gpkg"
    p = run([BIN, "--tiles", tiles, "-f", "GPKG", plans_only, src], check=False)
    assert p.returncode == 1 and not plans_only.exists()
    assert "nothing written" in p.stderr and "write the 'problems' layer to see them all" in p.stderr


@pytest.mark.parametrize("tiles", ["off", "on"])
def test_problems_layer_is_written_when_no_input_can_be_read(tmp_path, tiles):
    """Every input unreadable: the problems layer asked for names each file and its fault; the run fails."""
    folder = tmp_path / "bad"
    folder.mkdir()
    (folder / "a_empty.gml").write_text("")
    (folder / "b_garbage.gml").write_bytes(bytes(range(256)) * 4)
    out = tmp_path / "out.gpkg"
    p = run([BIN, "--tiles", tiles, "-f", "GPKG", out, folder, "ground_plans", "problems"], check=False)
    assert p.returncode == 1, p.stderr
    assert "only the 'problems' layer written" in p.stderr, p.stderr
    ds = ogr.Open(str(out))
    assert [ds.GetLayer(i).GetName() for i in range(ds.GetLayerCount())] == ["problems"]
    unreadable = {pathlib.Path(f["file"]).name: f["reason"] for f in ds.GetLayer(0) if f["code"] == "UNREADABLE_FILE"}
    assert set(unreadable) == {"a_empty.gml", "b_garbage.gml"}
    assert "empty" in unreadable["a_empty.gml"]


def test_whole_corpus_folder_as_one_input(tmp_path):
    """A folder of tiles where many are bad: the good buildings still come out, nothing is lost."""
    out, stats = tmp_path / "out.gpkg", tmp_path / "stats.json"
    p = run([BIN, "--stats", stats, "-f", "GPKG", out, CORPUS, "ground_plans", "footprints", "problems",
             "plan_members"], check=False)
    assert p.returncode == 0, p.stderr
    counts = json.loads(stats.read_text())["counts"]
    assert counts["footprints"] >= sum(1 for w in EXPECTED.values() if w["exit"] == 0)
    check_nothing_lost(out, counts)


def _real_inputs():
    """Every real sample: every CityGML file of sample_data/ and tests/data/, and each dataset folder of CityGML
    as one input (a folder of tiles); the same of the third-party samples, marked thirdparty_data."""
    from conftest import SHARED_DATA, THIRDPARTY_DATA, real_sample_files, thirdparty_data
    suffixes = (".gml", ".citygml", ".xml")

    def citygml(d):
        return [p for p in d.iterdir() if p.suffix.lower() in suffixes] if d.is_dir() else []

    def folders(root):
        return [d for d in sorted(p for p in root.iterdir() if p.is_dir()) if len(citygml(d)) > 1] if root.is_dir() else []
    # a third-party folder as one input where the repository holds only part of it
    thirdparty = real_sample_files(suffixes, True) + [d for d in folders(THIRDPARTY_DATA)
                                                       if len(citygml(d)) > len(citygml(SHARED_DATA / d.name))]
    return real_sample_files(suffixes) + folders(SHARED_DATA) + [pytest.param(p, marks=thirdparty_data)
                                                                  for p in thirdparty]


@pytest.mark.parametrize("src", _real_inputs(), ids=lambda p: f"{p.parent.name}/{p.name}")
def test_nothing_lost_on_real_data(tmp_path, src):
    """buildings in = footprints + buildings given up (each named by a problem), and every footprint is
    a member of a plan or has a union-stage problem: via --stats and the output layers."""
    out, stats = tmp_path / "out.gpkg", tmp_path / "stats.json"
    p = run([BIN, "--stats", stats, "-f", "GPKG", out, src, "ground_plans", "footprints", "problems",
             "plan_members"], check=False)
    assert p.returncode >= 0, p.stderr
    if p.returncode != 0:
        # Only a file with nothing usable may fail, and it must say so.
        assert "nothing usable" in p.stderr or "UNREADABLE" in p.stderr or src.name in p.stderr, p.stderr
        counts = json.loads(stats.read_text())["counts"] if stats.exists() else None
        assert counts is None or counts["footprints"] == 0
        return
    counts = json.loads(stats.read_text())["counts"]
    check_nothing_lost(out, counts)


def test_python_progress_callback_returning_false_stops_the_translation():
    """gdal.VectorTranslate with a callback that returns 0: GDAL stops with an error, nothing is left
    half-written in silence. (The pipeline itself runs inside the driver's Open, which GDAL 3.6 gives no
    progress callback: there the callback can only stop the writing; pipeline_test's
    CancelStopsTheWork covers cancelling the pipeline through the library's Progress.)"""
    from osgeo import gdal
    from conftest import PLATEAU
    calls = []

    def stop(complete, message, data):
        calls.append(complete)
        return 0

    out = "/vsimem/cancelled.gpkg"
    with pytest.raises(RuntimeError):  # GDAL 3.6 reports the stop (or what it left behind) as an error
        gdal.VectorTranslate(out, f"GROUNDPLAN:{PLATEAU}", format="GPKG", layers=["ground_plans"], callback=stop)
    assert len(calls) == 1  # asked once, stopped at once
    gdal.Unlink(out)

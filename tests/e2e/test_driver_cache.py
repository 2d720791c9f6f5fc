# SPDX-License-Identifier: MIT
"""The driver computes a result once per input and options in a process (issue 18, driver/src/result_cache.h),
and answers update access quietly. Each case runs in a fresh Python process with CPL_DEBUG=ON and counts the
driver's "GroundPlan: pipeline run N for ..." lines, so the cache of this test process plays no part."""
import os
import shutil
import subprocess
import sys
import textwrap

import pytest
from osgeo import gdal, ogr

from conftest import PLATEAU_SMALL, PLUGIN_DIR, SOURCE_DIR, gdal_env, run

gdal.UseExceptions()

PRELUDE = """
import sys, threading
from osgeo import gdal, ogr
gdal.UseExceptions()
def count(conn, **oo):
    ds = gdal.OpenEx(conn, gdal.OF_VECTOR, open_options=[f"{k}={v}" for k, v in oo.items()])
    return ds.GetLayerByName("ground_plans").GetFeatureCount()
"""


def run_script(body, **env):
    """Runs PRELUDE + body in a new Python with CPL_DEBUG=ON; returns (stdout, pipeline runs, cache hits)."""
    e = gdal_env()
    e.update(CPL_DEBUG="ON", **env)
    p = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(body)], capture_output=True, text=True,
                       env=e, timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    lines = p.stderr.splitlines()
    runs = [l for l in lines if "GroundPlan: pipeline run" in l]
    hits = [l for l in lines if "GroundPlan: cached result for" in l]
    return p.stdout, runs, hits


@pytest.fixture()
def sample(tmp_path):
    """A copy of a small PLATEAU tile in a folder of its own: a key no other test shares."""
    d = tmp_path / "tile"
    d.mkdir()
    f = d / PLATEAU_SMALL.name
    shutil.copy(PLATEAU_SMALL, f)
    return f


def test_repeated_opens_compute_once(sample):
    out, runs, hits = run_script(f"""
        a = [count("GROUNDPLAN:{sample}") for _ in range(3)]
        held = gdal.OpenEx("GROUNDPLAN:{sample}", gdal.OF_VECTOR)  # kept open while another opens
        b = count("GROUNDPLAN:{sample}", NUM_THREADS=1)            # thread count: same result, same key
        print(a + [b])
    """)
    counts = eval(out)
    assert len(set(counts)) == 1 and counts[0] > 0
    assert len(runs) == 1, runs
    assert len(hits) == 4
    assert str(sample) in runs[0]


def test_options_that_change_the_result_are_part_of_the_key(sample):
    out, runs, _ = run_script(f"""
        print([count("GROUNDPLAN:{sample}"), count("GROUNDPLAN:{sample}", PRESET="CFD"),
               count("GROUNDPLAN:{sample}", PRESET="CFD"), count("GROUNDPLAN:{sample}", MIN_AREA=1e9)])
    """)
    exact, cfd, cfd_again, none_left = eval(out)
    assert cfd == cfd_again and none_left == 0 and exact > 0
    assert len(runs) == 3, runs


def test_a_changed_input_is_computed_again(sample):
    out, runs, _ = run_script(f"""
        import os, shutil
        before = count("GROUNDPLAN:{sample}")
        # Same size, a later modification time: another content could hide behind an equal size.
        st = os.stat("{sample}")
        os.utime("{sample}", ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
        again = count("GROUNDPLAN:{sample}")
        # Files beside it that no reader opens (the output written next to the input, a log): nothing changes.
        gdal.VectorTranslate("{sample.parent}/plans.gpkg", gdal.OpenEx("GROUNDPLAN:{sample}", gdal.OF_VECTOR),
                             format="GPKG")
        open("{sample.parent}/run.log", "w").write("log")
        third = count("GROUNDPLAN:{sample}")
        fourth = count("GROUNDPLAN:{sample}")
        print([before, again, third, fourth])
    """)
    assert len(set(eval(out))) == 1
    assert len(runs) == 2, runs  # the change computed again; the files written beside it did not


def _kml_with_model(folder, size):
    """A KML placing one COLLADA box of `size` metres (models/box.dae beside it)."""
    (folder / "models").mkdir(exist_ok=True)
    dae = (SOURCE_DIR / "tests" / "corpus" / "bad" / "kml_models" / "good_box.dae").read_text()
    (folder / "models" / "box.dae").write_text(dae.replace("0 0 0 10 0 0 10 8 0 0 8 0 0 0 6 10 0 6 10 8 6 0 8 6",
                                                           f"0 0 0 {size} 0 0 {size} 8 0 0 8 0 0 0 6 {size} 0 6 "
                                                           f"{size} 8 6 0 8 6"))
    kml = folder / "city.kml"
    kml.write_text('<?xml version="1.0" encoding="UTF-8"?><kml xmlns="http://www.opengis.net/kml/2.2"><Document>'
                   '<Placemark id="BOX"><Model><Location><longitude>127.17</longitude><latitude>37.62</latitude>'
                   '<altitude>0</altitude></Location><Link><href>models/box.dae</href></Link></Model></Placemark>'
                   '</Document></kml>')
    return kml


def test_a_changed_linked_model_is_computed_again_a_file_beside_is_not(tmp_path):
    kml = _kml_with_model(tmp_path, 10)
    out, runs, hits = run_script(f"""
        def area():
            ds = gdal.OpenEx("GROUNDPLAN:{kml}", gdal.OF_VECTOR)
            return round(sum(f["area_m2"] for f in ds.GetLayerByName("ground_plans")), 3)
        first = area()
        gdal.VectorTranslate("{tmp_path}/plans.gpkg", gdal.OpenEx("GROUNDPLAN:{kml}", gdal.OF_VECTOR), format="GPKG")
        open("{tmp_path}/models/notes.txt", "w").write("not read")
        second = area()
        import pathlib, os
        dae = pathlib.Path("{tmp_path}/models/box.dae")
        dae.write_text(dae.read_text().replace(" 10 0 0 10 8 0 ", " 20 0 0 20 8 0 ").replace(" 10 0 6 10 8 6 ", " 20 0 6 20 8 6 "))
        third = area()
        fourth = area()
        print([first, second, third, fourth])
    """)
    first, second, third, fourth = eval(out)
    assert first == pytest.approx(80, rel=1e-3) and second == first
    assert third == pytest.approx(160, rel=1e-3) and fourth == third
    assert len(runs) == 2, runs  # the first open, and the one after the model changed


def test_concurrent_opens_of_one_key_compute_once(sample):
    out, runs, hits = run_script(f"""
        counts = []
        barrier = threading.Barrier(4)
        def open_one():
            barrier.wait()
            counts.append(count("GROUNDPLAN:{sample}"))
        threads = [threading.Thread(target=open_one) for _ in range(4)]
        for t in threads: t.start()
        for t in threads: t.join()
        print(counts)
    """)
    counts = eval(out)
    assert len(counts) == 4 and len(set(counts)) == 1 and counts[0] > 0
    assert len(runs) == 1, runs


def test_the_cache_is_bounded(sample, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    shutil.copy(PLATEAU_SMALL, other / "b.gml")
    body = f"""
        print([count("GROUNDPLAN:{sample}"), count("GROUNDPLAN:{other}/b.gml"), count("GROUNDPLAN:{sample}")])
    """
    _, runs, _ = run_script(body)
    assert len(runs) == 2, runs
    # One entry kept: the second input pushes the first out once its dataset is closed.
    _, runs, _ = run_script(body, GROUNDPLAN_CACHE_ENTRIES="1")
    assert len(runs) == 3, runs
    _, runs, _ = run_script(body, GROUNDPLAN_CACHE_MAX_MB="0")
    assert len(runs) == 3, runs
    # Turned off: every open computes.
    _, runs, hits = run_script(body, GROUNDPLAN_CACHE="NO")
    assert len(runs) == 3 and not hits, runs


def test_open_datasets_share_a_result_beyond_the_bound(sample):
    _, runs, hits = run_script(f"""
        held = gdal.OpenEx("GROUNDPLAN:{sample}", gdal.OF_VECTOR)
        print(count("GROUNDPLAN:{sample}"))
    """, GROUNDPLAN_CACHE_ENTRIES="0")
    assert len(runs) == 1 and len(hits) == 1, runs


def test_a_failed_run_is_not_kept(tmp_path):
    bad = tmp_path / "empty.gml"
    bad.write_text("")
    _, runs, _ = run_script(f"""
        for _ in range(2):
            try:
                gdal.OpenEx("GROUNDPLAN:{bad}", gdal.OF_VECTOR)
            except RuntimeError as e:
                print(e)
    """)
    assert len(runs) == 2, runs


def test_ogrinfo_listing_every_layer_computes_once(sample):
    p = subprocess.run(["ogrinfo", "--debug", "on", "-so", f"GROUNDPLAN:{sample}", "ground_plans", "footprints",
                        "problems", "plan_members"], capture_output=True, text=True, env=gdal_env(), timeout=600)
    assert p.returncode == 0, p.stderr
    assert p.stdout.count("Feature Count:") == 4
    assert sum("GroundPlan: pipeline run" in l for l in p.stderr.splitlines()) == 1


def test_update_access_is_answered_quietly(sample):
    """QGIS probes update access on every load: no error, and the layers stay read-only."""
    errors = []

    def handler(cls, num, msg):
        if cls >= gdal.CE_Warning:
            errors.append((cls, num, msg))

    gdal.PushErrorHandler(handler)
    try:
        ds = gdal.OpenEx(f"GROUNDPLAN:{sample}", gdal.OF_VECTOR | gdal.OF_UPDATE)
    finally:
        gdal.PopErrorHandler()
    assert errors == []
    assert ds is not None and ds.GetDriver().ShortName == "GroundPlan"
    lyr = ds.GetLayerByName("ground_plans")
    assert lyr.GetFeatureCount() > 0
    for cap in (ogr.OLCSequentialWrite, ogr.OLCRandomWrite, ogr.OLCDeleteFeature, ogr.OLCCreateField):
        assert not lyr.TestCapability(cap)
    n = lyr.GetFeatureCount()
    assert lyr.CreateFeature(ogr.Feature(lyr.GetLayerDefn())) == ogr.OGRERR_UNSUPPORTED_OPERATION
    assert lyr.GetFeatureCount() == n


DUMP = """
import json
ds = gdal.OpenEx("GROUNDPLAN:{src}", gdal.OF_VECTOR)
out = {{}}
for name in ("ground_plans", "footprints", "problems", "plan_members"):
    lyr = ds.GetLayerByName(name)
    out[name] = [[f.items(), bytes(f.GetGeometryRef().ExportToIsoWkb()).hex() if f.GetGeometryRef() else None]
                 for f in lyr]
out["crs"] = ds.GetLayerByName("ground_plans").GetSpatialRef().ExportToWkt()
print(json.dumps(out))
"""


def test_persistent_cache_serves_the_next_process_and_is_never_stale(sample, tmp_path):
    store = tmp_path / "store"
    dump = DUMP.format(src=sample)
    first, runs, _ = run_script(dump, GROUNDPLAN_CACHE_DIR=str(store))
    assert len(runs) == 1
    files = list(store.glob("*.gpresult"))
    assert len(files) == 1 and not list(store.glob("*.tmp*"))  # written whole, under its final name

    p = subprocess.run([sys.executable, "-c", PRELUDE + dump], capture_output=True, text=True, timeout=600,
                       env=dict(gdal_env(), CPL_DEBUG="ON", GROUNDPLAN_CACHE_DIR=str(store)))
    assert p.returncode == 0, p.stderr
    assert "GroundPlan: pipeline run" not in p.stderr and "read from" in p.stderr
    assert p.stdout == first  # every layer, field and coordinate the same as computed

    # Off by default: without the option the next process computes.
    _, runs, _ = run_script(dump)
    assert len(runs) == 1

    # The input changes (same size, new time): computed again, not read.
    st = os.stat(sample)
    os.utime(sample, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    _, runs, _ = run_script(dump, GROUNDPLAN_CACHE_DIR=str(store))
    assert len(runs) == 1
    assert len(list(store.glob("*.gpresult"))) == 2


def test_persistent_cache_ignores_files_of_another_key_or_damaged(sample, tmp_path):
    store = tmp_path / "store"
    dump = DUMP.format(src=sample)
    truth, runs, _ = run_script(dump, GROUNDPLAN_CACHE_DIR=str(store))
    [stored] = store.glob("*.gpresult")
    good = stored.read_bytes()

    # Another input's result under this key's file name (what a hash collision would give): not used.
    other = tmp_path / "other"
    other.mkdir()
    shutil.copy(PLATEAU_SMALL, other / "b.gml")
    other_store = tmp_path / "other_store"
    run_script(DUMP.format(src=other / "b.gml"), GROUNDPLAN_CACHE_DIR=str(other_store),
               GROUNDPLAN_CACHE_ENTRIES="0")
    [foreign] = other_store.glob("*.gpresult")
    for damaged in (foreign.read_bytes(), good[: len(good) // 2], good[:-1] + bytes([good[-1] ^ 1]) + b"x"):
        stored.write_bytes(damaged)
        out, runs, _ = run_script(dump, GROUNDPLAN_CACHE_DIR=str(store))
        assert len(runs) == 1, "a foreign or damaged file was used"
        assert out == truth
        stored.write_bytes(good)

# SPDX-License-Identifier: MIT
"""One OGR source read in feature ranges side by side (issue 22): one dataset handle per range, merged in feature
order, so that every layer written (CSV with WKT: plans, footprints, problems, plan members) is byte for byte the
one-thread output. The sources are real footprints (the CityGML samples' footprints as groundplan writes them)
converted by ogr2ogr, plus the cases where ranges must not be used or must be given up: a sparse GeoPackage,
several layers with hostile features, a shapefile with a deleted record, --group-by, a FlatGeobuf."""
import hashlib
import json

import pytest
from osgeo import ogr

from conftest import BIN, PLATEAU, SHARED_DATA, THIRDPARTY_DATA, run, thirdparty_data
from test_ogr_input import _hostile_gpkg

LAYERS = ["ground_plans", "footprints", "problems", "plan_members"]
LORUP_TILES = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
BERLIN_LOD2 = THIRDPARTY_DATA / "citygml1-berlin-lod2-libcitygml"


def csv_hashes(tmp_path, name, src, *flags):
    """md5 of each layer written as CSV with WKT, and the --stats JSON."""
    out = tmp_path / name
    stats = tmp_path / f"{name}.json"
    run([BIN, "-q", "--stats", stats, *flags, "-f", "CSV", "-lco", "GEOMETRY=AS_WKT", out, src, *LAYERS])
    return {layer: hashlib.md5((out / f"{layer}.csv").read_bytes()).hexdigest() for layer in LAYERS}, \
        json.loads(stats.read_text())


def one_and_many(tmp_path, src, *flags, range_features=7):
    """The one-thread reading and the reading on 3 threads in ranges of `range_features` (several a thread)."""
    one, one_stats = csv_hashes(tmp_path, "one", src, *flags, "--threads", "1", "--read-range-features", "-1")
    many, many_stats = csv_hashes(tmp_path, "many", src, *flags, "--threads", "3", "--read-range-features",
                                  str(range_features))
    assert one_stats["reading"]["chunks"] == 0 and many_stats["reading"]["threads"] == 3
    return one, many, many_stats["reading"]


@pytest.fixture(scope="module")
def real_footprints(tmp_path_factory):
    """The footprints groundplan makes of real city models (Lorup's four LoD1 tiles, Niiza, Berlin LoD2)."""
    d = tmp_path_factory.mktemp("real")
    out = {}
    for name, src in {"lorup": LORUP_TILES, "niiza": PLATEAU, "berlin": BERLIN_LOD2}.items():
        if src.exists():
            run([BIN, "-q", "-f", "GPKG", d / f"{name}.gpkg", src, "footprints"])
            out[name] = d / f"{name}.gpkg"
    if not out:
        pytest.skip("no real city model here")
    return out


def biggest(real):
    return real.get("lorup") or real[sorted(real)[0]]


FORMATS = {"shp": ("ESRI Shapefile", ".shp"), "gpkg": ("GPKG", ".gpkg"), "geojson": ("GeoJSON", ".geojson")}


@pytest.mark.parametrize("fmt", sorted(FORMATS))
@pytest.mark.parametrize("sample", ["lorup", "niiza", pytest.param("berlin", marks=thirdparty_data)])
def test_ranges_give_the_one_thread_files(tmp_path, real_footprints, sample, fmt):
    if sample not in real_footprints:
        pytest.skip(f"{sample} is not here")
    driver, ext = FORMATS[fmt]
    src = tmp_path / f"fp{ext}"
    run(["ogr2ogr", "-f", driver, src, real_footprints[sample], "footprints"])
    ds = ogr.Open(str(src))
    n = ds.GetLayer(0).GetFeatureCount()
    ds = None
    one, many, reading = one_and_many(tmp_path, src, "--id-field", "source_id", range_features=max(1, n // 12))
    assert reading["files_chunked"] == 1 and reading["chunks"] >= 12 and reading["read_whole"] == []
    assert many == one


def test_a_sparse_geopackage_is_cut_by_fid(tmp_path, real_footprints):
    """FIDs with gaps (every third row gone): the ranges are cut in FID space, some of them empty."""
    src = tmp_path / "sparse.gpkg"
    run(["ogr2ogr", "-f", "GPKG", "-preserve_fid", "-where", "fid % 3 <> 0 AND fid < 200 OR fid > 400", src,
         biggest(real_footprints), "footprints"])
    one, many, reading = one_and_many(tmp_path, src, range_features=5)
    assert reading["chunks"] > 20 and reading["read_whole"] == []
    assert many == one


def test_several_layers_with_hostile_features_keep_their_problems_in_order(tmp_path):
    src = tmp_path / "hostile.gpkg"
    _hostile_gpkg(src)
    one, many, reading = one_and_many(tmp_path, src, "--id-field", "name", range_features=2)
    assert reading["chunks"] == 6 and reading["read_whole"] == []  # 10 parts in 5 ranges, 2 roads in 1
    assert many == one


def test_a_shapefile_with_deleted_records_gives_the_one_thread_files(tmp_path, real_footprints):
    """.dbf records marked deleted (not repacked): GDAL's count and its seek by index leave them out alike."""
    src = tmp_path / "fp.shp"
    run(["ogr2ogr", "-f", "ESRI Shapefile", src, biggest(real_footprints), "footprints"])
    ds = ogr.Open(str(src), 1)
    for fid in (0, 7, 8, 20, 21, 22):
        ds.GetLayer(0).DeleteFeature(fid)
    ds = None
    one, many, reading = one_and_many(tmp_path, src, range_features=7)
    assert reading["chunks"] > 10 and reading["read_whole"] == []
    assert many == one


@pytest.mark.parametrize("flags, why", [
    (["--group-by", "source_id"], "--group-by"),
    (["--input-where", "fid > 3"], "--input-where"),
    (["--input-sql", "SELECT * FROM footprints"], "--input-sql"),
])
def test_flags_that_rule_ranges_out_are_said(tmp_path, real_footprints, flags, why):
    src = biggest(real_footprints)
    one, many, reading = one_and_many(tmp_path, src, *flags)
    assert reading["chunks"] == 0 and reading["read_whole"][0]["why"].startswith(why)
    assert many == one


def test_a_flatgeobuf_without_fast_seek_is_read_whole(tmp_path, real_footprints):
    src = tmp_path / "fp.fgb"
    run(["ogr2ogr", "-f", "FlatGeobuf", src, biggest(real_footprints), "footprints"])
    one, many, reading = one_and_many(tmp_path, src)
    assert reading["chunks"] == 0 and "OLCFastSetNextByIndex" in reading["read_whole"][0]["why"]
    assert many == one

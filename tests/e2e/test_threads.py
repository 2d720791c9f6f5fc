# SPDX-License-Identifier: MIT
"""City scale on every core (issue 14), as a user meets it: the same files whatever the threads and the
cut of a file into chunks (hashes of CSV WKT outputs of every layer, every real CityGML sample), --threads,
GDAL's GDAL_NUM_THREADS config option and the driver's NUM_THREADS open option, --stats "reading"."""
import hashlib
import json

import pytest
from osgeo import gdal

from conftest import BIN, SAMPLES, SHARED_DATA, THIRDPARTY_DATA, real_sample_files, run, thirdparty_data

LAYERS = ["ground_plans", "footprints", "problems", "plan_members"]


def real_inputs():
    files = real_sample_files((".gml", ".citygml"))
    # Folders: read side by side (CityJSON and CityJSONSeq files are read whole, but side by side too).
    folders = [SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles", SHARED_DATA / "citygml2-plateau-japan-lod1",
               SHARED_DATA / "cityjson-3dbag-cjseq"]
    thirdparty = [pytest.param(p, marks=thirdparty_data) for p in real_sample_files((".gml", ".citygml"), True)]
    return files + folders + thirdparty


def csv_hashes(tmp_path, name, src, *flags):
    """md5 of each layer written as CSV with WKT, and the --stats JSON; None when the run fails (exit 1)."""
    out = tmp_path / name
    stats = tmp_path / f"{name}.json"
    p = run([BIN, "-q", "--stats", stats, *flags, "-f", "CSV", "-lco", "GEOMETRY=AS_WKT", out, src, *LAYERS],
            check=False)
    if p.returncode != 0:
        return None, p.stderr
    return {layer: hashlib.md5((out / f"{layer}.csv").read_bytes()).hexdigest() for layer in LAYERS}, \
        json.loads(stats.read_text())


@pytest.mark.parametrize("src", real_inputs(), ids=lambda p: f"{p.parent.name}/{p.name}")
def test_same_files_whatever_the_threads_and_the_cut(tmp_path, src):
    one, one_stats = csv_hashes(tmp_path, "one", src, "--threads", "1", "--read-chunk-bytes", "-1")
    many, many_stats = csv_hashes(tmp_path, "many", src, "--threads", "3", "--read-chunk-bytes", "16384")
    if one is None:  # not an input on its own (no building): refused the same way
        assert many is None, many_stats
        return
    assert one_stats["reading"]["threads"] == 1 and one_stats["reading"]["chunks"] == 0
    assert many_stats["reading"]["threads"] == 3
    assert many == one


XML_SAMPLES = [SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles", SHARED_DATA / "citygml2-plateau-japan-lod1"] + [
    pytest.param(THIRDPARTY_DATA / p, marks=thirdparty_data)
    for p in ("citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml",
              "citygml-citygml4j-samples/lod2_buildings_v3.gml",
              "citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml")]


@pytest.mark.parametrize("src", XML_SAMPLES, ids=lambda p: p.name)
def test_same_files_whether_parsed_in_memory_or_streamed(tmp_path, src):
    """pugixml in memory (the default) and expat streaming (GROUNDPLAN_XML_IN_MEMORY_BYTES 0) give the same
    files, whole and in chunks; --stats says which files expat read."""
    cut = ["--threads", "3", "--read-chunk-bytes", "16384"]
    memory, memory_stats = csv_hashes(tmp_path, "memory", src, *cut)
    streamed, streamed_stats = csv_hashes(tmp_path, "streamed", src, *cut,
                                          "--config", "GROUNDPLAN_XML_IN_MEMORY_BYTES", "0")
    whole, _ = csv_hashes(tmp_path, "whole", src, "--threads", "1", "--read-chunk-bytes", "-1",
                          "--config", "GROUNDPLAN_XML_IN_MEMORY_BYTES", "0")
    assert memory is not None and memory == streamed == whole
    assert memory_stats["reading"]["xml_streamed"] == []
    assert streamed_stats["reading"]["xml_streamed"], streamed_stats["reading"]
    assert all(e["why"] == "parsing in memory is off" for e in streamed_stats["reading"]["xml_streamed"])


def test_threads_from_gdal_num_threads_and_flag(tmp_path):
    src = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    _, stats = csv_hashes(tmp_path, "cfg", src, "--config", "GDAL_NUM_THREADS", "2")
    assert stats["reading"]["threads"] == 2
    _, stats = csv_hashes(tmp_path, "flag", src, "--config", "GDAL_NUM_THREADS", "2", "--threads", "1")
    assert stats["reading"]["threads"] == 1  # the flag wins
    assert stats["reading"]["files"] == 4 and stats["reading"]["bytes"] > 4_000_000
    assert "cpu" in stats["timings_s"] and stats["timings_s"]["cpu"] > 0


def test_bad_thread_counts_are_refused_with_the_option_named(tmp_path):
    src = SAMPLES / "plateau-niiza" / "53392547_bldg_6697_op2.gml"
    p = run([BIN, "--config", "GDAL_NUM_THREADS", "lots", "-f", "GPKG", tmp_path / "o.gpkg", src], check=False)
    assert p.returncode == 1 and "GDAL_NUM_THREADS=lots" in p.stderr
    with pytest.raises(RuntimeError, match="NUM_THREADS=-2"):
        gdal.OpenEx(f"GROUNDPLAN:{src}", gdal.OF_VECTOR, open_options=["NUM_THREADS=-2"])


def test_driver_num_threads_gives_the_same_layers():
    src = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    rows = []
    for n in ("1", "ALL_CPUS"):
        ds = gdal.OpenEx(f"GROUNDPLAN:{src}", gdal.OF_VECTOR, open_options=[f"NUM_THREADS={n}"])
        lyr = ds.GetLayerByName("ground_plans")
        rows.append([(f.items(), f.GetGeometryRef().ExportToIsoWkt()) for f in lyr])
    assert len(rows[0]) > 100 and rows[0] == rows[1]


def test_a_zip_of_tiles_is_read_like_the_folder(tmp_path):
    import zipfile
    folder = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"
    archive = tmp_path / "tiles.zip"
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as z:
        for tile in sorted(folder.glob("*.gml")):
            z.write(tile, f"tiles/{tile.name}")
        z.writestr("../escape.gml", (folder / "LoD1_24065860_2_2021-01-25.gml").read_bytes())
        z.writestr("README.txt", "not an input")
    from_folder, _ = csv_hashes(tmp_path, "folder", folder)
    from_zip, stats = csv_hashes(tmp_path, "zip", archive)
    # Not README.txt; not "../escape.gml" either (GDAL's /vsizip/ listing leaves out entries outside the archive)
    assert stats["reading"]["files"] == 4
    assert from_zip["ground_plans"] == from_folder["ground_plans"]

# SPDX-License-Identifier: MIT
"""CityJSON and CityJSONSeq through the CLI, the driver and a folder (issue 16): the 3DBAG file and its
CityJSONSeq twin give the same plans by every route; --lod / LOD= take 3DBAG's "2.2" names."""
import json
import shutil

import pytest
from osgeo import gdal

from conftest import BIN, SHARED_DATA, layer_rows, run

BAG = SHARED_DATA / "cityjson-3dbag-cjseq"
BAG_JSON = BAG / "3dbag_b2.city.json"
BAG_SEQ = BAG / "3dbag_b2.city.jsonl"


def _plans(path):
    return sorted(wkb for _, wkb in layer_rows(path, "ground_plans"))


def test_cli_file_sequence_and_folder_give_the_same_plans(tmp_path):
    outs = []
    for i, src in enumerate((BAG_JSON, BAG_SEQ)):
        out = tmp_path / f"o{i}.gpkg"
        stats = tmp_path / f"s{i}.json"
        run([BIN, "--verify", "--stats", stats, "-f", "GPKG", out, src])
        s = json.loads(stats.read_text())
        assert s["counts"]["footprints"] == 2, s
        outs.append(out)
    assert _plans(outs[0]) and _plans(outs[0]) == _plans(outs[1])
    # A folder holding only the sequence (its .city.jsonl is an input name; other .json files are not).
    folder = tmp_path / "tiles"
    folder.mkdir()
    shutil.copy(BAG_SEQ, folder / "t.city.jsonl")
    (folder / "metadata.json").write_text('{"asset": {"version": "1.0"}}')
    run([BIN, "-f", "GPKG", tmp_path / "f.gpkg", folder, "ground_plans", "problems"])
    assert _plans(tmp_path / "f.gpkg") == _plans(outs[0])
    assert layer_rows(tmp_path / "f.gpkg", "problems") == []


def test_driver_and_lod_names(tmp_path):
    out = tmp_path / "d.gpkg"
    src = gdal.OpenEx(f"GROUNDPLAN:{BAG_JSON}", gdal.OF_VECTOR, open_options=["LOD=2.2"])
    gdal.VectorTranslate(str(out), src, format="GPKG", layers=["ground_plans", "problems"])
    src = None
    cli = tmp_path / "c.gpkg"
    run([BIN, "--lod", "2.2", "-f", "GPKG", cli, BAG_JSON])
    assert _plans(out) == _plans(cli)
    # The sample has only LoD 2.2: asking for 1.3 names both buildings in problems, nothing usable.
    p = run([BIN, "--lod", "1.3", "-f", "GPKG", tmp_path / "none.gpkg", BAG_JSON], check=False)
    assert p.returncode == 1
    assert p.stderr.count("NO_GEOMETRY_AT_LOD") == 2, p.stderr
    bad = run([BIN, "--lod", "2.22", "-f", "GPKG", tmp_path / "x.gpkg", BAG_JSON], check=False)
    assert bad.returncode == 1 and "--lod 2.22" in bad.stderr
    with pytest.raises(RuntimeError, match="LOD=7"):
        gdal.OpenEx(f"GROUNDPLAN:{BAG_JSON}", gdal.OF_VECTOR, open_options=["LOD=7"])
    # LOD=1.3 through the driver: no geometry at that LoD, both buildings are problems.
    ds = gdal.OpenEx(f"GROUNDPLAN:{BAG_JSON}", gdal.OF_VECTOR, open_options=["LOD=1.3"])
    assert ds.GetLayerByName("ground_plans").GetFeatureCount() == 0
    codes = [f.GetField("code") for f in ds.GetLayerByName("problems")]
    assert codes.count("NO_GEOMETRY_AT_LOD") == 2, codes

# SPDX-License-Identifier: MIT
"""A new CSV file of the plans written by several writers side by side (issue 14, driver/output/csv_slices.h) is,
byte for byte, the file one writer makes; options the slices cannot keep (a second layer, -lco CREATE_CSVT,
HEADERS, WRITE_BOM, ogr2ogr options across features, an existing file) keep one writer, and --stats says which
was used and why. No slice file is left beside it."""
import json

import pytest

from conftest import BIN, run


def write(folder, name, src, threads, *args):
    out, stats = folder / f"{name}.csv", folder / f"{name}.json"
    run([BIN, "-q", "--threads", str(threads), "--stats", stats, "-f", "CSV", out, src, *args])
    return out, json.loads(stats.read_text())


@pytest.mark.parametrize("lco", [["-lco", "GEOMETRY=AS_WKT"],
                                 ["-lco", "GEOMETRY=AS_WKT", "-lco", "LINEFORMAT=CRLF", "-lco", "SEPARATOR=SEMICOLON",
                                  "-lco", "STRING_QUOTING=ALWAYS"],
                                 []], ids=["wkt", "crlf-semicolon-quoted", "no-geometry"])
def test_slices_give_the_one_writer_file(tmp_path, parts, lco):
    one, one_stats = write(tmp_path, "one", parts, 1, *lco)
    many, many_stats = write(tmp_path, "many", parts, 4, *lco)
    assert one_stats["writer"] == {"writers": 1, "why_one": "one thread"}
    assert many_stats["writer"]["writers"] == 4, many_stats["writer"]
    plans = many_stats["counts"]["ground_plans"]
    assert plans > 4 * 8192 and plans == one_stats["counts"]["ground_plans"]
    a, b = one.read_bytes(), many.read_bytes()
    assert len(b.splitlines()) == plans + 1  # the header once, a line a plan (no field holds a line break)
    assert a == b, "the file written in slices differs from the one-writer file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["many.csv", "many.json", "one.csv", "one.json"], \
        "a slice file was left behind"


@pytest.mark.parametrize("option,why", [
    (["-lco", "CREATE_CSVT=YES"], "-lco CREATE_CSVT=YES"),
    (["-lco", "HEADERS=NO"], "-lco HEADERS=NO"),
    (["-where", "n_parts > 1"], "ogr2ogr option -where"),
    (["ground_plans", "problems"], "a CSV file of several layers")], ids=lambda o: str(o)[:24])
def test_options_the_slices_cannot_keep_keep_one_writer(tmp_path, parts, option, why):
    _, stats = write(tmp_path, "many", parts, 4, *option)  # two layers into one .csv: GDAL's affair, as before
    assert stats["writer"] == {"writers": 1, "why_one": why}


def test_an_existing_file_keeps_one_writer(tmp_path, parts):
    dst = tmp_path / "old.csv"
    dst.write_text("x\n")
    run([BIN, "-q", "--threads", "4", "--stats", tmp_path / "s.json", "-f", "CSV", "-overwrite", dst, parts])
    stats = json.loads((tmp_path / "s.json").read_text())
    assert stats["writer"]["writers"] == 1

# SPDX-License-Identifier: MIT
"""-s_srs / -a_srs and S_SRS= / A_SRS= (issue 16): the CRS of the source coordinates when a file's srsName is
wrong; ours to apply, so GDAL's ogr2ogr never sees them (it would reproject or relabel our output)."""
from osgeo import gdal, ogr

from conftest import BIN, SOURCE_DIR, layer_rows, run

WRONG = SOURCE_DIR / "tests" / "corpus" / "bad" / "crs_4326_on_metres.gml"  # EPSG:4326 over UTM 32N metres


def test_cli_flag_names_and_fixes_the_source_crs(tmp_path):
    refused = run([BIN, "-f", "GPKG", tmp_path / "r.gpkg", WRONG], check=False)
    assert refused.returncode == 1 and "-s_srs" in refused.stderr, refused.stderr
    outs = []
    for flag in ("-s_srs", "-a_srs"):
        out = tmp_path / f"{flag}.gpkg"
        run([BIN, flag, "EPSG:25832", "-f", "GPKG", out, WRONG])
        ds = ogr.Open(str(out))
        srs = ds.GetLayerByName("ground_plans").GetSpatialRef()
        assert srs is not None and srs.GetAuthorityCode(None) == "25832"
        outs.append(sorted(wkb for _, wkb in layer_rows(out, "ground_plans")))
    assert outs[0] and outs[0] == outs[1]
    # The open option gives the same plans.
    drv = tmp_path / "oo.gpkg"
    src = gdal.OpenEx(f"GROUNDPLAN:{WRONG}", gdal.OF_VECTOR, open_options=["S_SRS=EPSG:25832"])
    gdal.VectorTranslate(str(drv), src, format="GPKG", layers=["ground_plans"])
    src = None
    assert sorted(wkb for _, wkb in layer_rows(drv, "ground_plans")) == outs[0]

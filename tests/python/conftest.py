# SPDX-License-Identifier: MIT
"""Fixtures for the tests of the Python module (issue 23). They skip when the module was not built."""
import os
import pathlib
import sys

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("GROUNDPLAN_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
BUILD_DIR = pathlib.Path(os.environ.get("GROUNDPLAN_BUILD_DIR", SOURCE_DIR / "build"))
BIN = os.environ.get("GROUNDPLAN_BIN", str(BUILD_DIR / "bin" / "groundplan"))
PLUGIN_DIR = os.environ.get("GDAL_DRIVER_PATH", str(BUILD_DIR / "gdalplugins"))
SAMPLES = SOURCE_DIR / "sample_data"
PLATEAU = SAMPLES / "plateau-niiza" / "53395404_bldg_6697_op.gml"
PLATEAU_SMALL = SAMPLES / "plateau-niiza" / "53392547_bldg_6697_op2.gml"
LORUP = SAMPLES / "niedersachsen-lorup" / "LoD1_24065862_2_2021-01-25.gml"

if str(BUILD_DIR / "python") not in sys.path:
    sys.path.insert(0, str(BUILD_DIR / "python"))

# Skip the whole folder cleanly where the module was not built (no python3-dev / pybind11-dev).
groundplan = pytest.importorskip("groundplan", reason="the groundplan Python module was not built")


from synthetic_city import block_city, city  # noqa: E402,F401  (shared with tests/bench/python_union_bench.py)


def symdiff_rel(a, b):
    """Area of the symmetric difference of a and b, relative to a's area."""
    return a.symmetric_difference(b).area / max(a.area, 1e-300)

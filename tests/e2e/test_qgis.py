# SPDX-License-Identifier: MIT
"""groundplan in a real QGIS (issue 18), headless (QT_QPA_PLATFORM=offscreen): PyQGIS loads the driver's
layers and renders them, open options pass through the layer URI, the pipeline runs once per layer load +
iterate + render, and the Processing algorithm (qgis/groundplan_provider) writes what the CLI writes, reports
progress, stops when cancelled and fails with the CLI's message. Every QGIS step runs in a fresh process
(QGIS's application object is one per process). Skipped where PyQGIS or qgis_process is not installed;
packaging/install-deps.sh installs them, so CI runs these."""
import json
import os
import pathlib
import shutil
import subprocess
import sys
import textwrap

import pytest
from osgeo import gdal, ogr

from conftest import BIN, PLATEAU, PLATEAU_SMALL, SOURCE_DIR, gdal_env, run

gdal.UseExceptions()

BUILD_DIR = pathlib.Path(os.environ.get("GROUNDPLAN_BUILD_DIR", SOURCE_DIR / "build"))
PLUGIN_PARENT = SOURCE_DIR / "qgis"
# Debian's /usr/bin/qgis_process wrapper passes --noversioncheck, which qgis_process 3.22 refuses: call the
# binary behind it where there is one.
QGIS_PROCESS = shutil.which("qgis_process.bin") or shutil.which("qgis_process")


def _has_pyqgis():
    return subprocess.run([sys.executable, "-c", "import qgis.core"], capture_output=True).returncode == 0


pytestmark = pytest.mark.skipif(not _has_pyqgis(), reason="PyQGIS (python3-qgis) is not installed")

QGIS_PRELUDE = """
import json, os, sys
from qgis.core import QgsApplication
QgsApplication.setPrefixPath("/usr", True)
app = QgsApplication([], False)
app.initQgis()
"""


@pytest.fixture()
def qgis_env(tmp_path):
    """A QGIS environment of its own: settings in a scratch HOME, our GDAL plugin, Python module and QGIS plugin."""
    home = tmp_path / "home"
    (home / "run").mkdir(parents=True)
    os.chmod(home / "run", 0o700)
    env = gdal_env()
    env.update(HOME=str(home), XDG_RUNTIME_DIR=str(home / "run"), QT_QPA_PLATFORM="offscreen",
               QGIS_PLUGINPATH=str(PLUGIN_PARENT), CPL_DEBUG="ON",
               PYTHONPATH=os.pathsep.join(filter(None, [str(BUILD_DIR / "python"), str(PLUGIN_PARENT),
                                                        os.environ.get("PYTHONPATH")])))
    return env


def run_qgis(env, body):
    """Runs QGIS_PRELUDE + body; returns (the JSON body printed last on stdout, pipeline runs in the debug output)."""
    p = subprocess.run([sys.executable, "-c", QGIS_PRELUDE + textwrap.dedent(body)], capture_output=True, text=True,
                       env=env, timeout=600)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-4000:]
    runs = [l for l in p.stderr.splitlines() if "GroundPlan: pipeline run" in l]
    return json.loads(p.stdout.strip().splitlines()[-1]), runs, p.stderr


def cli_gpkg(tmp_path, src, *flags):
    out = tmp_path / "cli.gpkg"
    run([BIN, "-overwrite", *flags, "-f", "GPKG", out, src, "ground_plans", "footprints", "problems"])
    return out


def rows_of(path, layer):
    ds = ogr.Open(str(path))
    lyr = ds.GetLayerByName(layer)
    assert lyr is not None, f"{path} has no layer {layer}"
    out = []
    for f in lyr:
        g = f.GetGeometryRef()
        out.append((f.items(), bytes(g.ExportToIsoWkb()).hex() if g else None))
    return out, lyr.GetSpatialRef().GetAuthorityCode(None) if lyr.GetSpatialRef() else None


@pytest.fixture()
def sample(tmp_path):
    """The larger PLATEAU tile in a folder of its own (a cache key no other test shares)."""
    d = tmp_path / "tile"
    d.mkdir()
    shutil.copy(PLATEAU, d / PLATEAU.name)
    return d / PLATEAU.name


def test_layer_loads_renders_and_equals_the_cli(qgis_env, sample, tmp_path):
    png = tmp_path / "render.png"
    got, runs, _ = run_qgis(qgis_env, f"""
        from qgis.core import (QgsVectorLayer, QgsMapSettings, QgsMapRendererParallelJob, QgsFillSymbol)
        from qgis.PyQt.QtCore import QSize
        from qgis.PyQt.QtGui import QColor
        layer = QgsVectorLayer("GROUNDPLAN:{sample}|layername=ground_plans", "gp", "ogr")
        assert layer.isValid(), layer.error().summary()
        feats = [(f["gp_id"], f["area_m2"], bytes(f.geometry().asWkb()).hex()) for f in layer.getFeatures()]
        layer.setRenderer(layer.renderer().clone())
        layer.renderer().setSymbol(QgsFillSymbol.createSimple({{"color": "200,60,40", "outline_style": "no"}}))
        ms = QgsMapSettings()
        ms.setLayers([layer])
        ms.setDestinationCrs(layer.crs())
        ms.setExtent(layer.extent())
        ms.setOutputSize(QSize(400, 400))
        ms.setBackgroundColor(QColor(255, 255, 255))
        job = QgsMapRendererParallelJob(ms)  # QGIS Desktop's renderer: layers on worker threads
        job.start()
        job.waitForFinished()
        img = job.renderedImage()
        img.save("{png}")
        painted = sum(1 for x in range(0, img.width(), 2) for y in range(0, img.height(), 2)
                      if QColor(img.pixel(x, y)) != QColor(255, 255, 255))
        print(json.dumps({{"count": layer.featureCount(), "crs": layer.crs().authid(), "feats": feats,
                          "painted": painted, "pixels": (img.width() // 2) * (img.height() // 2)}}))
    """)
    cli, epsg = rows_of(cli_gpkg(tmp_path, sample), "ground_plans")
    assert got["crs"] == f"EPSG:{epsg}"
    assert got["count"] == len(cli) == len(got["feats"]) > 0
    by_id = {items["gp_id"]: (items, wkt) for items, wkt in cli}
    for gp_id, area, wkb in got["feats"]:
        items, cli_wkb = by_id[gp_id]
        assert area == items["area_m2"]
        assert wkb == cli_wkb, gp_id  # the same coordinates, bit for bit
    # Not blank, not flooded: buildings cover some of the map, not all of it.
    assert 0.01 * got["pixels"] < got["painted"] < 0.95 * got["pixels"]
    assert png.stat().st_size > 1000
    # Load, count, iterate and render (parallel job: its own connection) made one pipeline run.
    assert len(runs) == 1, runs


def test_open_options_through_the_layer_uri(qgis_env, sample, tmp_path):
    got, runs, _ = run_qgis(qgis_env, f"""
        from qgis.core import QgsVectorLayer
        n = {{}}
        for name, uri in [("exact", "GROUNDPLAN:{sample}|layername=ground_plans"),
                          ("cfd", "GROUNDPLAN:{sample}|layername=ground_plans|option:PRESET=cfd")]:
            layer = QgsVectorLayer(uri, name, "ogr")
            assert layer.isValid(), uri
            n[name] = [len(list(layer.getFeatures())), layer.featureCount()]
        print(json.dumps(n))
    """)
    exact, _ = rows_of(cli_gpkg(tmp_path, sample), "ground_plans")
    cfd, _ = rows_of(cli_gpkg(tmp_path, sample, "--preset", "cfd"), "ground_plans")
    assert len(cfd) != len(exact)  # the option made a difference, so passing it is tested
    assert got["exact"] == [len(exact)] * 2
    assert got["cfd"] == [len(cfd)] * 2
    assert len(runs) == 2, runs  # one per option set


def test_layer_load_logs_no_error(qgis_env, sample):
    got, _, stderr = run_qgis(qgis_env, f"""
        from qgis.core import QgsVectorLayer
        messages = []
        QgsApplication.messageLog().messageReceived.connect(lambda m, tag, level: messages.append([tag, m, int(level)]))
        for name in ("ground_plans", "footprints", "problems"):
            layer = QgsVectorLayer(f"GROUNDPLAN:{sample}|layername={{name}}", name, "ogr")
            assert layer.isValid()
            list(layer.getFeatures())
        app.processEvents()
        print(json.dumps(messages))
    """)
    assert [m for m in got if m[0] == "OGR" or "ERROR" in m[1]] == []
    assert not [l for l in stderr.splitlines() if l.startswith("ERROR")]
    assert "update access asked" in stderr  # QGIS did probe update access: the quiet answer was tested


def _qgis_process(env, *args):
    assert QGIS_PROCESS, "qgis_process is not installed"
    return subprocess.run([QGIS_PROCESS, *map(str, args)], capture_output=True, text=True, env=env, timeout=600)


@pytest.fixture()
def processing_env(qgis_env):
    if not QGIS_PROCESS:
        pytest.skip("qgis_process (Debian package qgis) is not installed")
    p = _qgis_process(qgis_env, "plugins", "enable", "groundplan_provider")
    assert p.returncode == 0, p.stdout + p.stderr
    return qgis_env


def test_qgis_process_writes_what_the_cli_writes(processing_env, sample, tmp_path):
    out = tmp_path / "qgis.gpkg"
    p = _qgis_process(processing_env, "run", "groundplan:groundplans", "--", f"INPUT={sample}",
                      f"OUTPUT=ogr:dbname='{out}' table=\"ground_plans\" (geom)",
                      f"FOOTPRINTS_OUTPUT=ogr:dbname='{out}' table=\"footprints\" (geom)",
                      f"PROBLEMS_OUTPUT=ogr:dbname='{out}' table=\"problems\"")
    assert p.returncode == 0, p.stdout + p.stderr
    cli = cli_gpkg(tmp_path, sample)
    for layer in ("ground_plans", "footprints", "problems"):
        ours, ours_epsg = rows_of(out, layer)
        theirs, theirs_epsg = rows_of(cli, layer)
        assert ours_epsg == theirs_epsg
        assert len(ours) == len(theirs) > 0 or layer == "problems"
        for (a, ga), (b, gb) in zip(ours, theirs):
            a.pop("fid", None)
            assert a == b
            assert (ga is None) == (gb is None)
            if ga:
                assert ogr.CreateGeometryFromWkb(bytes.fromhex(ga)).Equals(ogr.CreateGeometryFromWkb(bytes.fromhex(gb)))


def test_qgis_process_fails_with_the_cli_message(processing_env, tmp_path):
    missing = tmp_path / "missing.gml"
    cli = subprocess.run([BIN, "-f", "GPKG", tmp_path / "x.gpkg", missing], capture_output=True, text=True,
                         env=gdal_env())
    assert cli.returncode != 0
    message = cli.stderr.strip().splitlines()[-1].split(": ", 1)[-1]
    assert str(missing) in message
    p = _qgis_process(processing_env, "run", "groundplan:groundplans", "--", f"INPUT={missing}",
                      f"OUTPUT={tmp_path / 'q.gpkg'}")
    assert p.returncode != 0
    assert message in p.stdout + p.stderr


def test_algorithm_reports_progress_and_stops_when_cancelled(qgis_env, sample, tmp_path):
    got, _, _ = run_qgis(qgis_env, f"""
        sys.path.insert(0, "{PLUGIN_PARENT}")
        from qgis.core import QgsProcessingContext, QgsProcessingFeedback
        from groundplan_provider.algorithm import GroundPlansAlgorithm

        class Recorder(QgsProcessingFeedback):  # records progress and messages; cancel=True: Cancel at the first report
            def __init__(self, cancel=False):
                super().__init__()
                self.values, self.infos, self.cancel_first = [], [], cancel
                self.progressChanged.connect(self.seen)
            def seen(self, v):
                self.values.append(v)
                if self.cancel_first:
                    self.cancel()
            def pushInfo(self, info):
                self.infos.append(info)
                super().pushInfo(info)

        out = {{}}
        for name, cancel in (("full", False), ("cancelled", True)):
            alg = GroundPlansAlgorithm()
            alg.initAlgorithm()
            fb = Recorder(cancel)
            ctx = QgsProcessingContext()
            res, ok = alg.run({{"INPUT": "{sample}", "OUTPUT": "{tmp_path}/" + name + ".gpkg",
                               "FOOTPRINTS_OUTPUT": None, "PROBLEMS_OUTPUT": None}}, ctx, fb)
            out[name] = {{"ok": ok, "outputs": sorted(res or {{}}), "values": fb.values, "infos": fb.infos}}
        print(json.dumps(out))
    """)
    # Decided by what was reported and said, never by how far the work got before a cancel was seen.
    full, cancelled = got["full"], got["cancelled"]
    assert full["ok"] and full["outputs"] == ["OUTPUT"]
    v = full["values"]
    assert len(v) >= 2 and v == sorted(v) and v[-1] == 100
    assert 80 in v  # the pipeline's own end (PIPELINE_SHARE), then the writing's
    assert "Cancelled" not in full["infos"]
    # Cancel pressed at the first report: the pipeline stops there (groundplan.Cancelled, the algorithm says
    # "Cancelled"), nothing is reported after it, nothing is written.
    assert len(cancelled["values"]) == 1, cancelled["values"]
    assert "Cancelled" in cancelled["infos"], cancelled["infos"]
    assert cancelled["outputs"] == []


def test_algorithm_folder_preset_and_crs_match_the_driver(qgis_env, tmp_path):
    """FOLDER, PRESET and T_SRS reach the pipeline as the driver's FOLDER input, PRESET= and T_SRS= do."""
    folder = tmp_path / "tiles"
    folder.mkdir()
    shutil.copy(PLATEAU_SMALL, folder / "a.gml")
    shutil.copy(PLATEAU, folder / "b.gml")
    got, _, _ = run_qgis(qgis_env, f"""
        sys.path.insert(0, "{PLUGIN_PARENT}")
        from qgis.core import (QgsProcessingContext, QgsProcessingFeedback, QgsVectorLayer,
                               QgsCoordinateReferenceSystem)
        from groundplan_provider.algorithm import GroundPlansAlgorithm
        alg = GroundPlansAlgorithm()
        alg.initAlgorithm()
        res, ok = alg.run({{"FOLDER": "{folder}", "PRESET": 1, "T_SRS": QgsCoordinateReferenceSystem("EPSG:6677"),
                           "OUTPUT": "{tmp_path}/alg.gpkg", "FOOTPRINTS_OUTPUT": None, "PROBLEMS_OUTPUT": None}},
                          QgsProcessingContext(), QgsProcessingFeedback())
        assert ok, res
        print(json.dumps(res))
    """)
    ours, ours_epsg = rows_of(got["OUTPUT"].split("|")[0], pathlib.Path(got["OUTPUT"].split("layername=")[-1]).name
                              if "layername=" in got["OUTPUT"] else "alg")
    ds = gdal.OpenEx(f"GROUNDPLAN:{folder}", gdal.OF_VECTOR, open_options=["PRESET=CFD", "T_SRS=EPSG:6677"])
    lyr = ds.GetLayerByName("ground_plans")
    theirs = [(f.items(), bytes(f.GetGeometryRef().ExportToIsoWkb()).hex()) for f in lyr]
    assert ours_epsg == "6677"
    assert len(ours) == len(theirs) > 0
    exact_ds = gdal.OpenEx(f"GROUNDPLAN:{folder}", gdal.OF_VECTOR)  # kept: a layer dies with its dataset
    exact = exact_ds.GetLayerByName("ground_plans").GetFeatureCount()
    assert exact != len(theirs)  # the preset changed the result, so passing it is tested
    for (a, ga), (b, gb) in zip(ours, theirs):
        assert a == b
        assert ogr.CreateGeometryFromWkb(bytes.fromhex(ga)).Equals(ogr.CreateGeometryFromWkb(bytes.fromhex(gb)))


def test_saving_the_output_beside_the_input_does_not_compute_again(qgis_env, sample):
    """The usual QGIS session: load the plans, save them as a GeoPackage next to city.gml (and a log), load the
    layer again: one pipeline run. Then the input changes: computed again."""
    got, runs, _ = run_qgis(qgis_env, f"""
        import os
        from qgis.core import QgsVectorLayer, QgsVectorFileWriter, QgsCoordinateTransformContext
        def load():
            layer = QgsVectorLayer("GROUNDPLAN:{sample}|layername=ground_plans", "gp", "ogr")
            assert layer.isValid(), layer.error().summary()
            return layer, layer.featureCount()
        layer, first = load()
        opts = QgsVectorFileWriter.SaveVectorOptions()
        opts.driverName = "GPKG"
        err = QgsVectorFileWriter.writeAsVectorFormatV3(layer, "{sample.parent}/ground_plans.gpkg",
                                                        QgsCoordinateTransformContext(), opts)
        assert err[0] == QgsVectorFileWriter.NoError, err
        open("{sample.parent}/session.log", "w").write("saved")
        del layer
        layer, second = load()
        st = os.stat("{sample}")
        os.utime("{sample}", ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
        del layer
        layer, third = load()
        print(json.dumps([first, second, third, os.path.exists("{sample.parent}/ground_plans.gpkg")]))
    """)
    first, second, third, saved = got
    assert saved and first == second == third > 0
    assert len(runs) == 2, runs  # the first load and the one after the input changed; not the one after saving

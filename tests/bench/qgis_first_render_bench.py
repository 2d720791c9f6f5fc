#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Issue 18's timing goal: QGIS load-to-first-render of a GROUNDPLAN: layer within 1.2x of the CLI's time on
the same input. Not run in CI; figures in RESULTS.md.

    /usr/bin/python3 tests/bench/qgis_first_render_bench.py [SIZE_MB=150] [WORK_DIR=/tmp/gp-qgis-bench]

Generates a city of SIZE_MB with gen_big_citygml.py (kept for later runs), then times, each in a fresh
process and each REPEAT times (the best is reported, wall and CPU):
  cli:   groundplan -f GPKG out.gpkg city.gml (read, union, write ground_plans);
  qgis:  from QgsVectorLayer("GROUNDPLAN:city.gml|layername=ground_plans") to the first image of the whole
         layer by QgsMapRendererParallelJob (QGIS Desktop's renderer), QGIS's own start-up excluded (it is
         the same with any layer) but printed;
and prints the pipeline runs QGIS made (CPL_DEBUG) and the ratio qgis / cli. Needs a Release build in
build/ (or GROUNDPLAN_BUILD_DIR) and python3-qgis."""
import json
import os
import pathlib
import resource
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
SOURCE = HERE.parents[1]
BUILD = pathlib.Path(os.environ.get("GROUNDPLAN_BUILD_DIR", SOURCE / "build"))
REPEAT = int(os.environ.get("REPEAT", "2"))

QGIS_SCRIPT = r"""
import json, resource, sys, time
t_start = time.perf_counter()
from qgis.core import QgsApplication, QgsVectorLayer, QgsMapSettings, QgsMapRendererParallelJob
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor
QgsApplication.setPrefixPath("/usr", True)
app = QgsApplication([], False)
app.initQgis()
t_ready = time.perf_counter()
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
c0, t0 = cpu(), time.perf_counter()
layer = QgsVectorLayer("GROUNDPLAN:" + sys.argv[1] + "|layername=ground_plans", "gp", "ogr")
assert layer.isValid()
ms = QgsMapSettings()
ms.setLayers([layer])
ms.setDestinationCrs(layer.crs())
ms.setExtent(layer.extent())
ms.setOutputSize(QSize(1200, 1200))
ms.setBackgroundColor(QColor(255, 255, 255))
job = QgsMapRendererParallelJob(ms)
job.start()
job.waitForFinished()
img = job.renderedImage()
t1, c1 = time.perf_counter(), cpu()
img.save(sys.argv[2])
print(json.dumps({"wall_s": t1 - t0, "cpu_s": c1 - c0, "startup_s": t_ready - t_start,
                  "features": layer.featureCount()}))
"""


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def main():
    size_mb = float(sys.argv[1]) if len(sys.argv) > 1 else 150
    work = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else "/tmp/gp-qgis-bench")
    work.mkdir(parents=True, exist_ok=True)
    city = work / f"city_{int(size_mb)}mb.gml"
    if not city.exists():
        subprocess.run([sys.executable, HERE / "gen_big_citygml.py", city, str(size_mb)], check=True)
    env = dict(os.environ, GDAL_DRIVER_PATH=str(BUILD / "gdalplugins"), QT_QPA_PLATFORM="offscreen",
               CPL_DEBUG="ON")
    env.setdefault("XDG_RUNTIME_DIR", str(work / "run"))
    os.makedirs(env["XDG_RUNTIME_DIR"], mode=0o700, exist_ok=True)
    print(f"input: {city} ({city.stat().st_size / 1e6:.0f} MB), build {BUILD}, {os.cpu_count()} cores")

    cli, qgis = [], []
    for _ in range(REPEAT):
        c0, t0 = children_cpu(), time.perf_counter()
        subprocess.run([BUILD / "bin" / "groundplan", "-overwrite", "-f", "GPKG", work / "cli.gpkg", city],
                       check=True, capture_output=True, env=env)
        cli.append((time.perf_counter() - t0, children_cpu() - c0))
        p = subprocess.run(["/usr/bin/python3", "-c", QGIS_SCRIPT, str(city), str(work / "render.png")],
                           capture_output=True, text=True, env=env)
        assert p.returncode == 0, p.stderr[-3000:]
        q = json.loads(p.stdout.strip().splitlines()[-1])
        q["pipeline_runs"] = sum("GroundPlan: pipeline run" in l for l in p.stderr.splitlines())
        qgis.append(q)
    cli_wall, cli_cpu = min(w for w, _ in cli), min(c for _, c in cli)
    q_wall, q_cpu = min(q["wall_s"] for q in qgis), min(q["cpu_s"] for q in qgis)
    print(f"cli  wall {cli_wall:7.2f} s  cpu {cli_cpu:7.2f} s   (all runs: {cli})")
    print(f"qgis wall {q_wall:7.2f} s  cpu {q_cpu:7.2f} s   load to first render, {qgis[0]['features']} plans, "
          f"pipeline runs per load {[q['pipeline_runs'] for q in qgis]}, QGIS start-up "
          f"{min(q['startup_s'] for q in qgis):.2f} s (not counted)")
    print(f"ratio qgis/cli: wall {q_wall / cli_wall:.2f}  cpu {q_cpu / cli_cpu:.2f}  (goal: <= 1.2)")


if __name__ == "__main__":
    main()

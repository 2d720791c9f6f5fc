# SPDX-License-Identifier: MIT
"""Makes the screenshots of docs/qgis.md headless: the algorithm's dialog and a rendered result.

    QT_QPA_PLATFORM=offscreen GDAL_DRIVER_PATH=build/gdalplugins PYTHONPATH=build/python:qgis \\
        python3 qgis/screenshots.py sample_data/plateau-niiza/53395404_bldg_6697_op.gml docs/images
"""
import pathlib
import sys

from qgis.core import (QgsApplication, QgsFillSymbol, QgsMapRendererParallelJob, QgsMapSettings, QgsRectangle,
                       QgsVectorLayer)
from qgis.PyQt.QtCore import QSize
from qgis.PyQt.QtGui import QColor


def main(model, out_dir):
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    QgsApplication.setPrefixPath("/usr", True)
    app = QgsApplication([], True)
    app.initQgis()
    sys.path.insert(0, "/usr/share/qgis/python/plugins")
    from processing.core.Processing import Processing
    from processing.gui.AlgorithmDialog import AlgorithmDialog

    from groundplan_provider.provider import GroundPlanProvider

    Processing.initialize()
    provider = GroundPlanProvider()
    QgsApplication.processingRegistry().addProvider(provider)
    alg = QgsApplication.processingRegistry().createAlgorithmById("groundplan:groundplans")
    dialog = AlgorithmDialog(alg)
    dialog.resize(900, 640)
    dialog.show()
    app.processEvents()
    dialog.grab().save(str(out_dir / "qgis-algorithm-dialog.png"))
    dialog.close()

    # The result as QGIS draws it: ground plans over the footprints they were made of.
    plans = QgsVectorLayer(f"GROUNDPLAN:{model}|layername=ground_plans", "ground plans", "ogr")
    footprints = QgsVectorLayer(f"GROUNDPLAN:{model}|layername=footprints", "footprints", "ogr")
    assert plans.isValid() and footprints.isValid()
    plans.renderer().setSymbol(QgsFillSymbol.createSimple(
        {"color": "230,120,60,160", "outline_color": "120,40,10", "outline_width": "0.4"}))
    footprints.renderer().setSymbol(QgsFillSymbol.createSimple(
        {"style": "no", "outline_color": "40,40,40", "outline_width": "0.1", "outline_style": "dot"}))
    extent = plans.extent()
    centre = extent.center()
    w = extent.width() / 4  # a close-up of the middle, where plans merge several buildings
    ms = QgsMapSettings()
    ms.setLayers([footprints, plans])
    ms.setDestinationCrs(plans.crs())
    ms.setExtent(QgsRectangle(centre.x() - w / 2, centre.y() - w / 2, centre.x() + w / 2, centre.y() + w / 2))
    ms.setOutputSize(QSize(800, 800))
    ms.setBackgroundColor(QColor(255, 255, 255))
    job = QgsMapRendererParallelJob(ms)
    job.start()
    job.waitForFinished()
    job.renderedImage().save(str(out_dir / "qgis-result.png"))
    print(f"{plans.featureCount()} ground plans from {footprints.featureCount()} footprints in {plans.crs().authid()}")
    QgsApplication.processingRegistry().removeProvider(provider)
    app.exitQgis()


if __name__ == "__main__":
    main(*sys.argv[1:3])

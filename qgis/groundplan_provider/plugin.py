# SPDX-License-Identifier: MIT
"""The plugin object QGIS keeps: adds the provider to the Processing registry and removes it on unload.
initProcessing is what qgis_process calls (no GUI); QGIS Desktop calls initGui."""
from qgis.core import QgsApplication

from .provider import GroundPlanProvider


class GroundPlanPlugin:
    def __init__(self, iface):
        self.iface = iface
        self.provider = None

    def initProcessing(self):  # noqa: N802
        if self.provider is None:
            self.provider = GroundPlanProvider()
            QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None

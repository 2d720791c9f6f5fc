# SPDX-License-Identifier: MIT
"""The "GroundPlan" Processing provider: one algorithm, groundplan:groundplans."""
from qgis.core import QgsProcessingProvider

from .algorithm import GroundPlansAlgorithm


class GroundPlanProvider(QgsProcessingProvider):
    def id(self):
        return "groundplan"

    def name(self):
        return "GroundPlan"

    def longName(self):  # noqa: N802
        return "GroundPlan: ground plans from 3D city models"

    def loadAlgorithms(self):  # noqa: N802
        self.addAlgorithm(GroundPlansAlgorithm())

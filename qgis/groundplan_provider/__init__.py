# SPDX-License-Identifier: MIT
"""QGIS plugin entry point: registers the GroundPlan Processing provider (issue 18)."""


def classFactory(iface):  # noqa: N802 (QGIS's name)
    from .plugin import GroundPlanPlugin

    return GroundPlanPlugin(iface)

# SPDX-License-Identifier: MIT
"""Processing algorithm "Ground plans from 3D city model" (groundplan:groundplans): the CLI's parameters in,
its three layers out as feature sinks.

It drives the Python module (``groundplan._groundplan.read``) rather than the GDAL driver: the module runs the
same pipeline and builds the same layers as the CLI and the driver (the driver's dataset class), and it is
the route that reports progress and can be stopped, so QGIS's progress bar and Cancel button work. Errors
are the pipeline's own messages (the CLI prints the same text), raised as QgsProcessingException so that
QGIS shows them in its log."""
from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsFeature,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingException,
    QgsProcessingParameterCrs,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant

# The layers' fields as the CLI writes them (driver/src/ogr_groundplan_datasource.cpp); the algorithm checks
# the module's columns against them, so a field added there cannot go missing here unnoticed.
PLAN_FIELDS = [("gp_id", QVariant.LongLong), ("n_parts", QVariant.Int), ("area_m2", QVariant.Double),
               ("min_z", QVariant.Double), ("max_z", QVariant.Double), ("building_ids", QVariant.String),
               ("buildings", QVariant.String)]
FOOTPRINT_FIELDS = [("fp_id", QVariant.LongLong), ("source_id", QVariant.String), ("source_file", QVariant.String),
                    ("method", QVariant.String), ("gp_id", QVariant.LongLong), ("min_z", QVariant.Double),
                    ("max_z", QVariant.Double), ("building_id", QVariant.String)]
PROBLEM_FIELDS = [("source_id", QVariant.String), ("file", QVariant.String), ("stage", QVariant.String),
                  ("code", QVariant.String), ("reason", QVariant.String)]

FOOTPRINT_MODES = ["auto", "ground-surface", "decompose"]
PRESETS = ["none", "cfd"]
RESOLUTION_MODES = ["exact", "raster"]
DEVICES = ["auto", "cpu", "cuda"]
# Level-of-detail values: unset = the preset's (0 without one), as the CLI's --snap ... flags.
LOD_VALUES = [("SNAP", "Snap vertices and edges closer than (m)"),
              ("CLOSE_GAPS", "Close gaps narrower than (m)"),
              ("MIN_HOLE_AREA", "Fill holes smaller than (m²)"),
              ("MIN_AREA", "Drop ground plans smaller than (m²)"),
              ("SIMPLIFY", "Simplify with tolerance (m)")]
# Share of the progress bar the pipeline takes; the rest is handing the features to the sinks.
PIPELINE_SHARE = 80.0


def fields_of(spec):
    fields = QgsFields()
    for name, kind in spec:
        fields.append(QgsField(name, kind))
    return fields


class GroundPlansAlgorithm(QgsProcessingAlgorithm):
    INPUT = "INPUT"
    FOLDER = "FOLDER"
    OUTPUT = "OUTPUT"
    FOOTPRINTS_OUTPUT = "FOOTPRINTS_OUTPUT"
    PROBLEMS_OUTPUT = "PROBLEMS_OUTPUT"

    def name(self):
        return "groundplans"

    def displayName(self):  # noqa: N802
        return "Ground plans from 3D city model"

    def shortHelpString(self):  # noqa: N802
        return ("Reads a 3D city model (CityGML, CityJSON, KML/KMZ with COLLADA, glTF, or any OGR vector layer) "
                "and makes one valid polygon with holes for every group of touching or overlapping buildings: the "
                "exact union of their footprints. Give a file or a folder (every model in it is read). The "
                "problems table lists every building that is in no ground plan and why. The parameters are those "
                "of the groundplan command line tool (see `man groundplan`); the cfd preset prepares plans for "
                "simulation meshing (snap 0.01 m, close gaps 0.5 m, simplify 0.1 m, holes and plans under 1 m² "
                "dropped), and a level-of-detail value given here overrides the preset's.")

    def createInstance(self):  # noqa: N802
        return GroundPlansAlgorithm()

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterFile(
            self.INPUT, "3D city model file", behavior=QgsProcessingParameterFile.File, optional=True,
            fileFilter="3D city models (*.gml *.xml *.citygml *.gz *.json *.jsonl *.kml *.kmz *.gltf *.glb *.dae);;"
                       "Vector layers (*.gpkg *.shp *.geojson *.fgb);;All files (*)"))
        self.addParameter(QgsProcessingParameterFile(
            self.FOLDER, "or a folder of models", behavior=QgsProcessingParameterFile.Folder, optional=True))
        self.addParameter(QgsProcessingParameterEnum(
            "FOOTPRINTS", "Footprints", options=["auto (ground surfaces where present, else decompose)",
                                                 "ground surfaces only", "decompose the surfaces"],
            defaultValue=0))
        self.addParameter(QgsProcessingParameterNumber(
            "RESOLUTION", "Raster resolution (m, 0 = automatic; the result is exact)",
            type=QgsProcessingParameterNumber.Double, defaultValue=0.0, minValue=0.0))
        self.addParameter(QgsProcessingParameterEnum("PRESET", "Level-of-detail preset", options=PRESETS,
                                                     defaultValue=0))
        self.addParameter(QgsProcessingParameterCrs("T_SRS", "Target CRS (projected; default: the source's, "
                                                    "else its UTM zone)", optional=True))
        advanced = [
            QgsProcessingParameterString("LOD", "Level of detail to read (-1 = the highest each building has; "
                                         "CityJSON: 1.2, 2.2 ...)", defaultValue="-1"),
            QgsProcessingParameterEnum("RESOLUTION_MODE", "Resolution mode (raster: the paper's level of detail)",
                                       options=RESOLUTION_MODES, defaultValue=0),
            QgsProcessingParameterEnum("DEVICE", "Rasterise blocks on", options=DEVICES, defaultValue=0),
            QgsProcessingParameterString("S_SRS", "Source CRS, in place of the files' own (as -s_srs)",
                                         optional=True),
        ]
        for name, label in LOD_VALUES:
            advanced.append(QgsProcessingParameterNumber(name, label, type=QgsProcessingParameterNumber.Double,
                                                         minValue=0.0, optional=True))
        for p in advanced:
            p.setFlags(p.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
            self.addParameter(p)
        self.addParameter(QgsProcessingParameterFeatureSink(
            self.OUTPUT, "Ground plans", QgsProcessing.TypeVectorPolygon))
        self.addParameter(QgsProcessingParameterFeatureSink(
            self.FOOTPRINTS_OUTPUT, "Footprints", QgsProcessing.TypeVectorPolygon, optional=True,
            createByDefault=True))
        self.addParameter(QgsProcessingParameterFeatureSink(
            self.PROBLEMS_OUTPUT, "Problems", QgsProcessing.TypeVector, optional=True, createByDefault=True))

    def open_options(self, parameters, context):
        """The GroundPlan driver's open options (the CLI's flags map onto the same ones) for these parameters."""
        oo = {
            "FOOTPRINTS": FOOTPRINT_MODES[self.parameterAsEnum(parameters, "FOOTPRINTS", context)],
            "RESOLUTION": repr(self.parameterAsDouble(parameters, "RESOLUTION", context)),
            "PRESET": PRESETS[self.parameterAsEnum(parameters, "PRESET", context)],
            "RESOLUTION_MODE": RESOLUTION_MODES[self.parameterAsEnum(parameters, "RESOLUTION_MODE", context)],
            "DEVICE": DEVICES[self.parameterAsEnum(parameters, "DEVICE", context)],
            "LOD": self.parameterAsString(parameters, "LOD", context) or "-1",
        }
        crs = self.parameterAsCrs(parameters, "T_SRS", context)
        if crs.isValid():
            oo["T_SRS"] = crs.authid() or crs.toWkt(QgsCoordinateReferenceSystem.WKT_PREFERRED)
        s_srs = self.parameterAsString(parameters, "S_SRS", context)
        if s_srs:
            oo["S_SRS"] = s_srs
        for name, _ in LOD_VALUES:
            if parameters.get(name) is not None:  # unset: the preset decides
                oo[name] = repr(self.parameterAsDouble(parameters, name, context))
        return oo

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        try:
            from groundplan import _groundplan
        except ImportError as e:
            raise QgsProcessingException(
                f"the groundplan Python module cannot be imported ({e}): install the groundplan package, or from "
                "a source build start QGIS with PYTHONPATH=<build>/python") from e
        inputs = [p for p in (self.parameterAsFile(parameters, self.INPUT, context),
                              self.parameterAsFile(parameters, self.FOLDER, context)) if p]
        if not inputs:
            raise QgsProcessingException("Give a 3D city model file or a folder of models")
        oo = self.open_options(parameters, context)
        feedback.pushInfo(f"groundplan {' '.join(inputs)} with " + " ".join(f"{k}={v}" for k, v in oo.items()))

        last_text = [None]

        def progress(fraction, message):
            if message and message != last_text[0]:
                last_text[0] = message
                feedback.setProgressText(message)
            feedback.setProgress(PIPELINE_SHARE * fraction)
            return not feedback.isCanceled()

        try:
            r = _groundplan.read(inputs, oo, progress)
        except _groundplan.Cancelled:
            feedback.pushInfo("Cancelled")
            return {}
        except (ValueError, OSError, RuntimeError) as e:
            raise QgsProcessingException(str(e)) from e

        crs = QgsCoordinateReferenceSystem.fromWkt(r["crs_wkt"]) if r["crs_wkt"] else QgsCoordinateReferenceSystem()
        layers = r["layers"]
        outputs = {}
        todo = [(self.OUTPUT, "ground_plans", PLAN_FIELDS, QgsWkbTypes.Polygon),
                (self.FOOTPRINTS_OUTPUT, "footprints", FOOTPRINT_FIELDS, QgsWkbTypes.MultiPolygon),
                (self.PROBLEMS_OUTPUT, "problems", PROBLEM_FIELDS, QgsWkbTypes.NoGeometry)]
        total = sum(len(next(iter(layers[lname]["columns"].values()), [])) for _, lname, _, _ in todo) or 1
        done = 0
        for param, lname, spec, wkb_type in todo:
            layer = layers[lname]
            names = [n for n, _ in spec]
            if list(layer["columns"].keys()) != names:
                raise QgsProcessingException(f"the groundplan module's {lname} fields {list(layer['columns'])} "
                                             f"are not the ones this plugin writes {names}: update the plugin")
            fields = fields_of(spec)
            sink, dest = self.parameterAsSink(parameters, param, context, fields, wkb_type, crs)
            if sink is None:
                if param == self.OUTPUT:
                    raise QgsProcessingException(self.invalidSinkError(parameters, param))
                continue
            cols = [layer["columns"][n] for n in names]
            geoms = layer["geometry"]
            n = len(cols[0]) if cols else 0
            for i in range(n):
                if feedback.isCanceled():
                    return {}
                f = QgsFeature(fields)
                f.setAttributes([c[i] for c in cols])
                if geoms is not None and geoms[i] is not None:
                    g = QgsGeometry()
                    g.fromWkb(geoms[i])
                    f.setGeometry(g)
                if not sink.addFeature(f, QgsFeatureSink.FastInsert):
                    raise QgsProcessingException(self.writeFeatureError(sink, parameters, param))
                done += 1
                if done % 1000 == 0:
                    feedback.setProgress(PIPELINE_SHARE + (100 - PIPELINE_SHARE) * done / total)
            outputs[param] = dest
        stats = r["stats"]
        n_problems = len(layers["problems"]["columns"]["code"])
        feedback.pushInfo(f"{stats['buildings_read']} buildings read, "
                          f"{len(layers['ground_plans']['columns']['gp_id'])} ground plans in {r['crs_name']}, "
                          f"{n_problems} problems")
        if n_problems:
            feedback.pushWarning(f"{n_problems} buildings or notes are in the problems table: "
                                 "see its code and reason columns")
        feedback.setProgress(100)
        return outputs

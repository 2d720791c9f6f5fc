// SPDX-License-Identifier: MIT
#pragma once
// Any OGR vector source as input (issue 22): Shapefile, GeoPackage, GeoJSON, FlatGeobuf, OSM, File
// Geodatabase, PostGIS connection strings, /vsizip/ paths ... whatever this GDAL reads, except the city
// formats (CityGML, KML, glTF, COLLADA), which keep their own readers, and our own GroundPlan driver.
//
// Each feature is one building (or, with group_by, each value of a field is one):
//   Polygon / MultiPolygon / CurvePolygon ... whose faces are all horizontal (2D, or Z at one level per
//   face): a Mesh of SurfaceKind::FootPrint faces, so the footprint takes the explicit path as given;
//   PolyhedralSurface, TIN, MultiPatch (read by GDAL as MultiPolygon Z or a collection of TINs) and
//   MultiPolygon Z with walls: a Mesh of SurfaceKind::Unknown faces (the bottom of the solid where it
//   has one, else decomposition: the same --footprints option as for CityGML).
// Curves are linearised (GDAL's default step). Points, lines, empty or unreadable geometries, NaN or
// huge coordinates: a Problem naming the layer and the FID; the rest of the layer goes on. Invalid
// polygons (self-crossing rings) pass as they are.
//
// A layer with several geometry fields (SQLite, PostGIS, CSV with GEOM_POSSIBLE_NAMES ...): one is read,
// the one geom_field names, else the first; a NOTE names the ones left out. Its CRS is the layer's.
//
// Coordinates come in the layer's data axis order (GDAL's traditional GIS order: x = longitude or
// easting) and in ONE source CRS per file: the first selected layer's; other layers in another CRS are
// transformed into it by GDAL. The caller turns that CRS into the working frame (ReadInfo::source_srs).
//
// Thread-safety: each call opens its own dataset handle and keeps no global state; several files may
// be read at once on different threads.
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::gis {

struct OgrInputOptions {
  std::vector<std::string> layers;        // --input-layer / INPUT_LAYERS: layers to read; empty = every layer
  std::string where;                      // --input-where / INPUT_WHERE: OGR SQL attribute filter on each layer
  std::string sql;                        // --input-sql / INPUT_SQL: a statement whose result is the one layer read
  std::string dialect;                    // --input-dialect / INPUT_DIALECT: SQL dialect ("", "OGRSQL", "SQLITE")
  std::vector<std::string> open_options;  // --input-oo / INPUT_OO: NAME=VALUE open options of the source's driver
  std::string id_field;                   // --id-field / ID_FIELD: building id; empty = the FID
  std::string group_by;                   // --group-by / GROUP_BY: features sharing this field's value are one building
  std::string geom_field;                 // --input-geom-field / INPUT_GEOM_FIELD: the geometry field read; empty = the first
  std::size_t max_vertices = 50'000'000;  // a feature with more vertices is a Problem TOO_MANY_VERTICES
  double max_abs_coordinate = 1e9;        // as CityGmlOptions: beyond it a feature is COORDINATE_OUT_OF_RANGE
};

struct OgrInfo {
  std::string driver;                 // GDAL driver short name, e.g. "ESRI Shapefile"
  std::vector<std::string> layers;    // layers read
  std::string source_srs;             // the file's CRS (EPSG:n or WKT2) as PROJ takes it; empty = none
  bool east_north = true;             // data x is longitude / easting (GDAL's traditional GIS order)
  std::size_t features = 0;           // features read (each a member of a building, or a Problem)
  std::size_t features_bad = 0;       // of those, the ones that are a Problem instead
  std::size_t buildings = 0;          // meshes delivered
};

/// True when GDAL (any vector driver but GroundPlan) identifies `path`: a file, folder, /vsi path or
/// connection string (PG:...). Does not throw.
bool ogr_can_read(const std::string& path);

/// "PG:dbname=x", "WFS:http..." ...: a GDAL connection string rather than a file name (a drive letter
/// is not one).
bool looks_like_connection_string(const std::string& path);

/// Reads every selected layer of `path`. `source_srs_ready` is called once, before the first mesh,
/// when info.source_srs and info.east_north are set. Throws InputError naming the source when GDAL
/// cannot open it, when a named layer or field is missing, or when -where/-sql is refused; per-feature
/// defects are Problems (stage "read", source_id = the feature's id, code NOT_AREAL, EMPTY_GEOMETRY,
/// BAD_COORDINATES, COORDINATE_OUT_OF_RANGE, TOO_MANY_VERTICES, NO_CRS, TRANSFORM_FAILED), and a layer
/// whose reading stops on a GDAL error gets UNREADABLE_FEATURES. Exceptions thrown by `on_mesh` propagate.
void read_ogr(const std::string& path, const OgrInputOptions& options, const std::function<void()>& source_srs_ready,
              const std::function<void(Mesh&&)>& on_mesh, std::vector<Problem>& problems, OgrInfo& info);

}  // namespace groundplan::gis

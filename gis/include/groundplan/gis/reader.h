// SPDX-License-Identifier: MIT
#pragma once
// One entry point for every input format (DESIGN.md stage 1-2, issue 6). The format is chosen by
// extension, and by content where the extension says nothing (.xml, no extension, /vsi paths):
//   .gml .citygml .xml     CityGML        meshes as written (info.in_working_crs == false): the caller
//                                         transforms them with a WorkingFrame from info.citygml.srs_name
//   .kml .kmz              KML + COLLADA  meshes in the working CRS (placed with GeographicLib + PROJ)
//   .gltf .glb             glTF           meshes in the working CRS (ECEF georeference, else origin)
//   .dae                   COLLADA alone  meshes in the working CRS; needs ReadOptions::origin
//   tileset.json .b3dm     3D Tiles       meshes in the working CRS (ECEF after the tile transforms); tiles3d.h
//   .cmpt (a folder with a tileset.json: that tileset)
//   .city.json, .json      CityJSON       as CityGML: meshes as written, CRS in info.citygml.srs_name
//   .city.jsonl, .jsonl    CityJSONSeq    (metadata.referenceSystem); .json only with "type": "CityJSON"
//   anything else GDAL     OGR layers     meshes as written in the file's one source CRS (info.source_srs,
//   reads as vector data                  GDAL's data axis order in info.source_axis); issue 22, ogr_input.h
// The working CRS of self-georeferenced formats is ReadOptions::target_srs when given, else the
// WGS 84 UTM zone of the first model's anchor; it is in info.working_crs once a mesh was placed.
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/cityjson.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/gltf.h>
#include <groundplan/gis/kml.h>
#include <groundplan/gis/ogr_input.h>
#include <groundplan/gis/tiles3d.h>
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis {

enum class InputFormat { Unknown, CityGml, Kml, Kmz, Collada, Gltf, Glb, CityJson, CityJsonSeq, Ogr, Tiles3d };
const char* to_string(InputFormat format);

struct ReadOptions {
  int lod = -1;                 // CityGML, CityJSON: -1 = the highest LoD each building has
  int lod_refinement = -1;      // CityJSON: with lod, the digit after the point (3DBAG "2.2"); -1 = the highest
  std::string target_srs;       // working CRS for KML/glTF/COLLADA (-t_srs, or the first file's); empty = UTM
  std::string origin;           // "lon,lat[,alt]" for glTF without georeference and bare .dae; empty = none
  KmlOptions kml;               // byte limits (KMZ), COLLADA limits
  GltfOptions gltf;
  Tiles3dOptions tiles3d;       // its gltf member is ReadOptions::gltf (copied in by read_any)
  OgrInputOptions ogr;          // any OGR vector source: layers, filter, ids, grouping (issue 22)
  // CityGML, CityJSON: told the file's bytes as they are read (progress; a .gz's packed bytes, scaled from
  // the unpacked ones read: gzip_progress.h); may be empty
  std::function<void(std::uint64_t)> on_bytes;
  CityJsonOptions cityjson;     // limits (lod and lod_refinement above win over its own)
  /// A gzip input (is_gzip_input_name) may expand to at most this many times its compressed size, and at
  /// least gzip_min_bytes: a gzip bomb then stops with an InputError naming the file instead of filling
  /// memory or disk (deflate reaches ~1000:1 on repeated bytes; CityGML and CityJSON give 5-30:1).
  std::uint64_t gzip_max_ratio = 100;
  std::uint64_t gzip_min_bytes = std::uint64_t{64} << 20;
};

struct ReadInfo {
  std::string file;
  InputFormat format = InputFormat::Unknown;
  bool in_working_crs = false;  // meshes arrive in working_crs (KML, glTF, COLLADA); false: as written (CityGML)
  WorkingCrs working_crs;       // valid when in_working_crs and something was placed
  std::vector<std::string> notes;  // georeference notes (UTM zone chosen ...)
  // When !in_working_crs: the CRS the meshes are written in (CityGML srsName, an OGR layer's EPSG:n or
  // WKT; empty = none) and, where the format fixes it, their axis order (Auto: the CRS's rule).
  std::string source_srs;
  AxisOrder source_axis = AxisOrder::Auto;
  SourceInfo citygml;           // CityGML; for CityJSON: srs_name (referenceSystem), envelope (geographicalExtent)
  CityJsonInfo cityjson;        // CityJSON / CityJSONSeq only
  KmlInfo kml;                  // KML/KMZ only
  GltfInfo gltf;                // glTF only
  Tiles3dInfo tiles3d;          // 3D Tiles only
  OgrInfo ogr;                  // OGR sources only
  std::size_t meshes = 0;       // meshes delivered
};

/// The format of `path`: by extension, else by its first bytes (zip -> Kmz, "glTF" -> Glb, "b3dm"/"cmpt"
/// -> Tiles3d, XML root <kml>/<COLLADA>/CityGML namespace, '{' with "asset" and "root" -> Tiles3d, with
/// "asset" alone -> Gltf; a file named tileset.json -> Tiles3d). Unknown when nothing fits.
InputFormat detect_format(const std::string& path);
/// The same from a file name and its first bytes (for a driver's Identify). Does not throw.
InputFormat detect_format(const std::string& name, std::string_view head);
/// True for the extensions a folder of tiles is expanded to (.gml .citygml .xml .kml .kmz .gltf .glb
/// .b3dm .i3dm .cmpt .city.json .city.jsonl; a folder holding a tileset.json is that tileset instead; not .dae: a .dae beside a .kml is the KML's model, not a second input; not
/// plain .json: a tile folder holds other JSON, e.g. 3D Tiles' tileset.json).
bool is_input_name(const std::string& name);
/// The names is_input_name takes, for messages: "*.gml, *.citygml, ..., *.city.jsonl.gz".
std::string input_name_patterns();
/// A gzip-compressed input by its name (issue 16): `x.gml.gz`, `x.citygml.gz`, `x.xml.gz`, `x.city.json.gz`,
/// `x.city.jsonl.gz`, `x.kml.gz` (any case). Such a file is read through GDAL's /vsigzip/.
bool is_gzip_input_name(const std::string& name);
/// The path GDAL opens for `path`: "/vsigzip/" + path for a gzip input named as above (not already a
/// /vsi path); else `path` itself.
std::string open_path(const std::string& path);

/// Reads one file of any supported format (a file the city formats do not recognise goes to GDAL's
/// vector drivers: identified by content, so connection strings and /vsi paths work too). `info.format` and `info.in_working_crs` are set before
/// the first mesh is delivered. Per-building defects are Problems. Throws InputError naming the file
/// when it cannot be read at all, when its format is unknown, or when a glTF / COLLADA file has no
/// georeference and no origin was given ("pass --origin lon,lat,alt"); InvalidArgument for a bad
/// origin or target CRS. Exceptions thrown by `on_mesh` propagate.
void read_any(const std::string& path, const ReadOptions& options, const MeshCallback& on_mesh,
              std::vector<Problem>& problems, ReadInfo& info);

}  // namespace groundplan::gis

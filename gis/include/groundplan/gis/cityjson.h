// SPDX-License-Identifier: MIT
#pragma once
// CityJSON 1.0 / 1.1 / 2.0 and CityJSONSeq reader (issue 16): Building and BuildingPart geometry into
// one groundplan::Mesh each, in the coordinates the file writes (after its "transform"); the CRS is
// metadata.referenceSystem (CityJSONSeq: the first line's), which gis/crs.h turns into the working
// frame exactly as a CityGML srsName.
//
// Parser: simdjson. A valid CityJSON file is parsed once into simdjson's DOM (its runtime-dispatched
// kernel) and converted from it, so it is held whole: bytes, tape and index, ~6 bytes a byte, files up
// to 4 GiB (simdjson's limit). Why not streamed: its "vertices" may follow "CityObjects" (3DBAG), and
// simdjson 3.0.1's On-Demand also needs the whole document and a structural index of it before the
// first value (README, "Memory and speed"). A file with a broken object is read again object by object.
// CityJSONSeq is read line by line, one DOM per line: memory is bounded by the longest line, whatever
// the file's size.
//
// What becomes a mesh: every Building / BuildingPart with surface geometry (MultiSurface,
// CompositeSurface, Solid, MultiSolid, CompositeSolid, GeometryInstance of such a template). A
// BuildingPart's mesh has parent_id = its first "parents" entry. A Building with "children" and no
// geometry of its own yields none (its parts carry it), as in the CityGML reader. Semantic surfaces
// map to SurfaceKind (GroundSurface -> Ground ...); MeshFace::lod is the LoD's integer part.
//
// Hostile input: nesting is limited (max_depth), numbers out of double range, vertex indices out of
// range, templates out of range and coordinates beyond max_abs_coordinate drop the surface with a
// Problem naming the object; malformed JSON inside one object (CityJSON) or one line (CityJSONSeq)
// drops that object or line with a Problem, and the rest is read.
#include <groundplan/gis/citygml.h>  // MeshCallback
#include <groundplan/types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis {

struct CityJsonOptions {
  /// -1: per object, the highest LoD it has ("2.2" > "2" > "1.3"); 0..4: only that LoD, and of its
  /// refinements (3DBAG's "1.2", "1.3", "2.2") the highest unless lod_refinement (0..9) names one.
  int lod = -1;
  int lod_refinement = -1;
  /// Nesting deeper than this is malformed (CityJSON needs ~12 levels; attributes may nest a little).
  std::size_t max_depth = 128;
  /// A CityJSONSeq line longer than this is skipped with a Problem LINE_TOO_LONG.
  std::size_t max_line_bytes = std::size_t{1} << 30;
  /// As CityGmlOptions::max_abs_coordinate: a surface with a coordinate beyond it is dropped.
  double max_abs_coordinate = 1e9;
  /// Bytes read (unpacked) after which reading stops with InputError; 0: no limit. read_any sets it for a
  /// gzip input (ReadOptions::gzip_max_ratio), so that a gzip bomb cannot fill memory.
  std::uint64_t max_bytes = 0;
  /// Told the bytes as they are read (1 MiB at a time; unpacked for a gzip input), for progress; may be empty.
  std::function<void(std::uint64_t)> on_bytes;
};

struct CityJsonInfo {
  std::string version;           // "1.0", "1.1", "2.0" as written
  bool sequence = false;         // CityJSONSeq
  std::string reference_system;  // metadata.referenceSystem as written; empty if none
  bool has_extent = false;       // metadata.geographicalExtent [minx, miny, minz, maxx, maxy, maxz]
  double extent[6] = {0, 0, 0, 0, 0, 0};
  std::size_t city_objects = 0;  // all city objects met
  std::size_t buildings = 0;     // Building objects
  std::size_t building_parts = 0;
  std::size_t meshes = 0;
  std::size_t buildings_dropped = 0;  // Buildings/parts given up, each with a Problem naming it
  std::size_t vertices = 0;      // vertices read (CityJSONSeq: over all features)
  std::size_t features = 0;      // CityJSONSeq lines with a CityJSONFeature
  std::uint64_t bytes = 0;
};

/// Reads a CityJSON file (`path`: any GDAL VSI path). Throws InputError naming the file when it
/// cannot be opened, is not JSON, is not CityJSON ("type" is not "CityJSON"), is larger than 4 GiB
/// ("convert it to CityJSONSeq"), or breaks off (meshes delivered before stay delivered).
/// Per-object defects are Problems (stage "read"). Exceptions thrown by `on_mesh` propagate.
void read_cityjson(const std::string& path, const CityJsonOptions& options, const MeshCallback& on_mesh,
                   std::vector<Problem>& problems, CityJsonInfo& info);

/// Reads a CityJSONSeq file (first line "type":"CityJSON" with transform, CRS and templates, then one
/// "CityJSONFeature" per line) in constant memory. Throws InputError when the file cannot be opened or
/// its first line is not a CityJSON header; a bad later line is a Problem BAD_LINE and reading goes on.
void read_cityjson_seq(const std::string& path, const CityJsonOptions& options, const MeshCallback& on_mesh,
                       std::vector<Problem>& problems, CityJsonInfo& info);

/// Cheap sniff of the first bytes: a JSON object whose "type" is "CityJSON". `sequence` is set when a
/// later line holds a "CityJSONFeature". Does not throw.
bool looks_like_cityjson(std::string_view head, bool* sequence = nullptr);

}  // namespace groundplan::gis

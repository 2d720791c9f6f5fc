// SPDX-License-Identifier: MIT
#pragma once
// Streaming CityGML 1.0 / 2.0 / 3.0 reader (DESIGN.md stage 1, issue 6): Building and BuildingPart
// geometry into one groundplan::Mesh each, in the coordinates and axis order the file writes (the
// CRS is the srsName in SourceInfo; gis/crs.h turns it into the working frame).
//
// Memory is bounded by the buildings in flight (plus two bounded xlink look-aside buffers), never by
// the file: a file of gigabytes streams through expat in 1 MiB chunks.
//
// Security: no DTD is loaded, no external entity is resolved, and any entity declaration stops the
// parse (billion laughs, XXE); the XML nesting depth is limited.
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis {

struct CityGmlOptions {
  /// -1: per building, the highest LoD it has (faces without a LoD are always kept);
  /// 0..4: only that LoD (a building without it becomes a Problem NO_GEOMETRY_AT_LOD).
  int lod = -1;
  /// XML nesting deeper than this is an InputError (CityGML with ADEs stays well under 100).
  std::size_t max_depth = 512;
  /// Look-aside for xlink:href targets in buildings already delivered (backward references across
  /// buildings): the most recent buildings' faces, up to this many vertices. 0 disables it.
  std::size_t xlink_index_max_vertices = 2'000'000;
  /// Buildings whose xlink targets were not found yet are held back (forward references) up to this
  /// many; beyond that (and at the end of the file) they are delivered with XLINK_TARGET_MISSING.
  std::size_t max_pending_buildings = 256;
  /// A coordinate list (posList, pos, coordinates) longer than this many characters drops its polygon
  /// (BAD_COORDINATES): text is kept only up to this, whatever a count or srsDimension claims (issue 8).
  std::size_t max_coordinate_chars = 64u << 20;
  /// A polygon with a coordinate beyond this magnitude is dropped (COORDINATE_OUT_OF_RANGE): no CRS on
  /// Earth has values past 1e9 (metres or degrees); such numbers would only break the later stages.
  double max_abs_coordinate = 1e9;
  /// A document (a file, or one chunk of a large file) of at most this many bytes is read into memory and
  /// parsed by pugixml, 4-5x faster than expat, with the same result; larger ones, and any document pugixml
  /// would read differently (a DOCTYPE, another encoding, malformed XML), are streamed through expat. Memory
  /// for a document read so: about three times its size (the bytes, pugixml's copy, its tree). 0: always expat.
  std::size_t dom_max_bytes = 64u << 20;
  /// Told the bytes of the file as they are read (progress across files); may be empty.
  std::function<void(std::uint64_t)> on_bytes;
};

/// What the reader learnt about one file.
struct SourceInfo {
  std::string file;
  std::string citygml_version;     // "1.0", "2.0", "3.0"; empty when the file is not CityGML
  std::string srs_name;            // the first srsName in the file, as written; empty if none
  bool srs_mixed = false;          // another srsName differs from srs_name (geometries keep their numbers)
  std::string other_srs_name;      // the first such other srsName
  int srs_dimension = 0;           // the first srsDimension attribute seen, 0 if none
  bool has_envelope = false;       // the first gml:Envelope, as written (CRS axis order)
  double envelope_lower[3] = {0, 0, 0};
  double envelope_upper[3] = {0, 0, 0};
  std::size_t buildings = 0;       // Building elements met
  std::size_t building_parts = 0;  // BuildingPart elements met
  std::size_t meshes = 0;          // meshes delivered to the callback
  std::size_t buildings_dropped = 0;  // buildings (parts) given up, each with a Problem naming it (NO_GEOMETRY,
                                      // NO_GEOMETRY_AT_LOD, TRUNCATED): meshes + buildings_dropped = all met
  std::size_t faces = 0;           // faces in those meshes
  std::size_t xlinks_resolved = 0;
  std::size_t xlinks_missing = 0;
  std::uint64_t bytes = 0;         // bytes parsed
  std::uint64_t bytes_streamed = 0;  // of those, the bytes expat streamed (the rest pugixml parsed in memory)
  std::string streamed_why;          // why the first streamed document was not parsed in memory
};

/// Called once per Building / BuildingPart mesh. A BuildingPart's mesh has parent_id set; a Building
/// with parts and geometry of its own yields a mesh too; a Building with parts and no geometry of its
/// own yields none (its parts carry it). Vertices are as written: x, y, z in the axis order of the
/// srsName (EPSG:6697 writes lat, lon, h). The mesh may be moved from.
using MeshCallback = std::function<void(Mesh&&)>;

/// Reads `path` (any GDAL VSI path works too: /vsigzip/, /vsizip/, /vsimem/).
/// Per-building defects (ring of < 3 points, NaN/Inf, unparseable numbers, missing xlink target,
/// no geometry) are appended to `problems` (stage "read") and reading goes on. A building that is given
/// up (no mesh delivered) has a Problem NO_GEOMETRY, NO_GEOMETRY_AT_LOD or TRUNCATED; other codes name
/// defects of buildings still delivered. A file that is not
/// CityGML (no CityGML namespace) yields no meshes and one Problem NOT_CITYGML.
/// Throws InputError naming the file when it cannot be opened or is not well-formed XML (truncated,
/// garbage, empty), or is hostile (entity declarations, nesting too deep); meshes delivered before the
/// error stay delivered, buildings complete but held back for a forward xlink are delivered before the
/// throw, and buildings open at the error get a Problem TRUNCATED. Exceptions thrown by `on_mesh` propagate (e.g. Cancelled).
void read_citygml(const std::string& path, const CityGmlOptions& options, const MeshCallback& on_mesh,
                  std::vector<Problem>& problems, SourceInfo& info);

/// The same on a document in memory; `name` stands for the file in messages and Mesh::source_file.
void read_citygml_buffer(std::string_view xml, const std::string& name, const CityGmlOptions& options,
                         const MeshCallback& on_mesh, std::vector<Problem>& problems, SourceInfo& info);

/// Cheap sniff of the first bytes (a CityGML namespace URI and a CityModel or Building element):
/// for a driver's Identify. Does not throw.
bool looks_like_citygml(std::string_view head);

}  // namespace groundplan::gis

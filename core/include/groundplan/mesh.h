// SPDX-License-Identifier: MIT
#pragma once
// A building part as the readers deliver it (DESIGN.md stage 1): 3D polygon faces in one frame, with
// semantic hints. Flat arrays so that a city of millions of faces is a few allocations, not millions.
#include <cstdint>
#include <string>
#include <vector>

namespace groundplan {

struct Point3 {
  double x = 0, y = 0, z = 0;
  friend bool operator==(const Point3&, const Point3&) = default;
};

/// What the source says a face is. Readers set it where the format says so (CityGML thematic
/// surfaces, lod0FootPrint); decomposition (paper §4) does not trust it.
enum class SurfaceKind : std::uint8_t {
  Unknown = 0,   // geometry without semantics (lod1Solid, lod2MultiSurface, COLLADA triangles)
  Ground,        // CityGML GroundSurface
  Roof,          // RoofSurface
  Wall,          // WallSurface
  Closure,       // ClosureSurface
  FootPrint,     // CityGML lod0FootPrint (2D/2.5D ground outline given outright)
  RoofEdge,      // CityGML lod0RoofEdge (roof outline projected; not a footprint)
  Other,         // any other thematic surface (OuterCeiling, OuterFloor, Door, Window, ...)
};

/// One face: rings [first_ring, first_ring + ring_count) of the mesh; the first is the outer ring,
/// the rest are holes. Ring r holds vertex indices indices[ring_offsets[r] .. ring_offsets[r+1]),
/// without the repeated closing vertex.
struct MeshFace {
  std::uint32_t first_ring = 0;
  std::uint32_t ring_count = 0;
  SurfaceKind kind = SurfaceKind::Unknown;
  std::uint8_t lod = 0;          // 0..4 where the source says; 255 = unknown
};

struct Mesh {
  std::vector<Point3> vertices;
  std::vector<std::uint32_t> indices;
  std::vector<std::uint32_t> ring_offsets{0};  // size = number of rings + 1
  std::vector<MeshFace> faces;

  std::string source_id;    // gml:id of the Building/BuildingPart, Placemark id, node name ...
  std::string parent_id;    // gml:id of the Building a BuildingPart belongs to; empty otherwise
  std::string source_file;
  std::string name;         // gml:name or similar, may be empty
  double measured_height = -1;  // metres, < 0 if absent

  std::size_t ring_count() const { return ring_offsets.size() - 1; }

  /// Appends a face from rings of points (outer first). Returns its index.
  std::uint32_t add_face(const std::vector<std::vector<Point3>>& rings, SurfaceKind kind, std::uint8_t lod) {
    MeshFace f;
    f.first_ring = static_cast<std::uint32_t>(ring_count());
    f.ring_count = static_cast<std::uint32_t>(rings.size());
    f.kind = kind;
    f.lod = lod;
    for (const auto& ring : rings) {
      for (const auto& p : ring) {
        indices.push_back(static_cast<std::uint32_t>(vertices.size()));
        vertices.push_back(p);
      }
      ring_offsets.push_back(static_cast<std::uint32_t>(indices.size()));
    }
    faces.push_back(f);
    return static_cast<std::uint32_t>(faces.size() - 1);
  }
};

}  // namespace groundplan

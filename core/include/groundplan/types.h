// SPDX-License-Identifier: MIT
#pragma once
// Plain data shared by every stage (DESIGN.md "Data flows one way"). No GDAL, PROJ or CUDA types.
#include <cstdint>
#include <string>
#include <vector>

namespace groundplan {

/// A point in the working CRS: projected, metric (metres), x = easting, y = northing.
struct Point2 {
  double x = 0;
  double y = 0;
  friend bool operator==(const Point2&, const Point2&) = default;
};

/// A closed ring without the repeated closing vertex.
using Ring = std::vector<Point2>;

/// A polygon with holes. For OUTPUT polygons (GroundPlan) the outer ring is counter-clockwise and
/// every hole clockwise (y up). INPUT polygons (Footprint) may have any orientation, repeated
/// points, self-intersections or zero area: the union engine copes with them.
struct Polygon {
  Ring outer;
  std::vector<Ring> holes;
};

/// The 2D footprint of one building (or building part), in the working CRS.
struct Footprint {
  std::vector<Polygon> polygons;  // a building may stand on several disjoint ground polygons
  std::string source_id;          // gml:id, KML Placemark id, glTF node name ...
  std::string source_file;
  std::string method;             // how it was found: to_string(FootprintMethod), e.g. "ground-surface"
  double min_z = 0;               // lowest / highest vertex height of the source mesh (metres)
  double max_z = 0;
  std::string parent_id;          // the Building a BuildingPart belongs to (Mesh::parent_id); empty for a Building
};

/// The id of the Building a footprint belongs to: its parent's for a BuildingPart, else its own.
inline const std::string& building_id_of(const Footprint& f) { return f.parent_id.empty() ? f.source_id : f.parent_id; }

/// One connected region of the union of footprints: exactly one outer ring (CCW) and its holes (CW).
struct GroundPlan {
  Polygon polygon;
  std::vector<std::uint32_t> members;  // indices into the footprint vector the plan was built from, ascending
  double area_m2 = 0;
};

/// A building (or part of one) that could not be used, or a note about something changed.
/// Nothing is dropped silently: every input building is a member of a plan or has a Problem.
struct Problem {
  std::string source_id;  // gml:id or similar; empty if the defect is not tied to one building
  std::string file;
  std::string stage;      // "read", "footprint", "union", ...
  std::string code;       // stable upper-case code, e.g. "NO_GROUND_GEOMETRY"
  std::string reason;     // one sentence for a person
};

}  // namespace groundplan

// SPDX-License-Identifier: MIT
#pragma once
// Mesh -> Footprint (DESIGN.md stage 3). The explicit path takes what the source says outright:
// CityGML GroundSurface faces, else lod0FootPrint faces, else the bottom of an LoD1/LoD2 solid or
// closed multi-surface (faces horizontal within a tolerance, at the mesh's lowest level, facing
// down). Surface decomposition (paper §4) is issue 5.
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <string>

namespace groundplan {

enum class FootprintSource {
  Auto,           // explicit geometry; decomposition where that fails (once issue 5 lands)
  GroundSurface,  // explicit geometry only: GroundSurface, lod0FootPrint, the bottom of a solid
  Decompose,      // surface decomposition (paper §4): not implemented yet
};

/// How the footprint was found.
enum class FootprintMethod { None, GroundSurface, FootPrint, SolidBottom, Decomposition };
const char* to_string(FootprintMethod method);

struct FootprintParams {
  FootprintSource source = FootprintSource::Auto;
  /// A face counts as horizontal when its normal is within this angle of vertical.
  double horizontal_tolerance_deg = 10.0;
  /// Bottom faces: horizontal faces whose highest vertex is at most this far above the lowest
  /// horizontal down-facing face (metres).
  double level_tolerance_m = 0.5;
  /// Faces whose 2D area is below this (m²) are ignored (vertical faces mislabelled as ground ...).
  double min_face_area_m2 = 1e-6;
};

struct FootprintResult {
  bool ok = false;
  Footprint footprint;           // polygons (x, y of the mesh: the working CRS), source id and file, z range
  FootprintMethod method = FootprintMethod::None;
  std::string code;              // when !ok: "NO_GROUND_GEOMETRY", "NOT_IMPLEMENTED", "EMPTY_MESH"
  std::string reason;            // when !ok: one sentence for the Problem
};

/// The footprint of one building (part). Never throws for bad geometry: !ok with a reason instead.
/// Polygons keep the faces' holes; orientation as in the source (the union engine accepts any).
FootprintResult make_footprint(const Mesh& mesh, const FootprintParams& params = {});

}  // namespace groundplan

// SPDX-License-Identifier: MIT
#pragma once
// Mesh -> Footprint (DESIGN.md stage 3). The explicit path takes what the source says outright:
// CityGML GroundSurface faces, else lod0FootPrint faces, else the bottom of an LoD1/LoD2 solid or
// closed multi-surface (faces horizontal within a tolerance, at the mesh's lowest level, facing
// down). Surface decomposition (paper §4, issue 5) finds it from the mesh alone.
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <string>

namespace groundplan {

enum class FootprintSource {
  Auto,           // explicit geometry where the source has it, else surface decomposition
  GroundSurface,  // explicit geometry only: GroundSurface, lod0FootPrint, the bottom of a solid
  Decompose,      // surface decomposition (paper §4, issue 5) only; ignores what the source says
};

/// How the footprint was found. DecompositionShadow: the decomposition's lower boundary closed no
/// loop (a model that is not watertight), so the footprint is the mesh's shadow (the union of its
/// facets' vertical projections), which also covers any overhang.
enum class FootprintMethod { None, GroundSurface, FootPrint, SolidBottom, Decomposition, DecompositionShadow };
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
  /// Decomposition: facets within this angle of the horizontal proxy plane are floors / ceilings,
  /// the rest walls (paper §4). Raise it where floors follow steep terrain.
  double proxy_tolerance_deg = 20.0;
  /// Decomposition: vertices closer than this are welded (triangle soup, per-polygon copies) and a
  /// vertex this close to another facet's edge splits it (T-junctions). Metres.
  double weld_tolerance_m = 1e-3;
};

struct FootprintResult {
  bool ok = false;
  Footprint footprint;           // polygons (x, y of the mesh: the working CRS), source id and file, z range
  FootprintMethod method = FootprintMethod::None;
  std::string code;              // when !ok: "NO_GROUND_GEOMETRY" (auto, ground-surface), "NO_FOOTPRINT_LOOP"
                                 // (decompose), "EMPTY_MESH"
  std::string reason;            // when !ok: one sentence for the Problem
  std::string note;              // when ok but found by a last resort (the shadow): why the earlier methods failed
  /// When ok by surface decomposition or a solid's bottom: the footprint checked against the building's lowest horizontal faces;
  /// non-empty when it leaves out ground the building stands on (FOOTPRINT_MISSES_GROUND), with the areas.
  std::string misses_ground;
};

/// The footprint of one building (part). Never throws for bad geometry: !ok with a reason instead.
/// Polygons keep the faces' holes; orientation as in the source (the union engine accepts any).
FootprintResult make_footprint(const Mesh& mesh, const FootprintParams& params = {});

}  // namespace groundplan

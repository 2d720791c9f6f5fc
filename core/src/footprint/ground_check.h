// SPDX-License-Identifier: MIT
#pragma once
// A footprint checked against what the building's own geometry says, independently of how the footprint was
// found: the lowest horizontal faces (the floor the building stands on) must lie inside it. A footprint that
// leaves part of them out misses ground the building stands on (a decomposition that took a tower for the
// whole of a building on a plinth): a defect, reported with the areas (FOOTPRINT_MISSES_GROUND). Overhangs,
// arcades and recessed ground floors are no defect: their upper storeys are not the lowest faces.
// One pass over the faces and, for the lowest ones, a point test per triangle of their fans: a small share
// of reading the building (tests/bench/ground_check_bench.cpp).
#include <groundplan/footprint.h>
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <string>
#include <vector>

namespace groundplan::footprint {

struct GroundCheck {
  double footprint_m2 = 0;   // area of the footprint's polygons
  double lowest_m2 = 0;      // the lowest horizontal faces' areas (within level_tolerance_m of the lowest point),
                             // summed: a low slab's top and bottom both count
  double uncovered_m2 = 0;   // plan area under them outside the footprint, each place once
  double zmin = 0;           // the building's lowest point
  double level_m = 0;        // the level tolerance the lowest faces were taken within
  /// Over 0.1 % of the ground that footprint and lowest faces cover together, and over 0.01 m², is left out.
  bool misses_ground() const { return uncovered_m2 > 1e-3 * (footprint_m2 + uncovered_m2) && uncovered_m2 > 0.01; }
  /// One sentence for the Problem.
  std::string reason() const;
};

GroundCheck check_ground(const Mesh& mesh, const std::vector<Polygon>& footprint, const FootprintParams& params);

}  // namespace groundplan::footprint

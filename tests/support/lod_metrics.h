// SPDX-License-Identifier: MIT
#pragma once
// Measurements of ground plans for the level-of-detail tests and report (issue 9), with GEOS as the
// independent judge: validity, overlaps, small holes, neighbours closer than a distance, and what a
// GEOS closing would still add (a gap narrower than D left behind shows up there).
#include <groundplan/types.h>

#include <cstddef>
#include <vector>

namespace groundplan::testing {

struct LodMetrics {
  std::size_t plans = 0;
  std::size_t holes = 0;
  std::size_t vertices = 0;
  double area_m2 = 0;                   // sum of plan areas (GEOS)
  std::size_t invalid = 0;              // plans GEOSisValid rejects
  std::size_t overlapping_pairs = 0;    // pairs of plans whose interiors overlap (GEOS relate)
  std::size_t small_holes = 0;          // holes below small_hole_m2
  std::size_t close_pairs = 0;          // pairs of plans closer than near_m (and not touching)
  double closing_residual_m2 = -1;      // area GEOS buffer(+D/2, mitre) -> buffer(-D/2, mitre) of the plans
                                        // adds to them; -1 when not asked (gap_m = 0)
};

/// Measures `plans`. small_hole_m2, near_m: thresholds for small_holes and close_pairs (0 = skip);
/// gap_m > 0: computes closing_residual_m2 with a GEOS closing of width gap_m (mitre limit 10).
LodMetrics measure_plans(const std::vector<GroundPlan>& plans, double small_hole_m2, double near_m, double gap_m);

}  // namespace groundplan::testing

// SPDX-License-Identifier: MIT
#pragma once
// Helpers for the union engine's tests: footprints from WKT, the engine run against GEOS.
#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <string>
#include <vector>

namespace groundplan::testing {

/// One footprint from a POLYGON or MULTIPOLYGON WKT.
Footprint footprint_from_wkt(const std::string& wkt, const std::string& id = "");
/// Footprints, one per WKT.
std::vector<Footprint> footprints_from_wkt(const std::vector<std::string>& wkts);

struct UnionCheck {
  std::vector<GroundPlan> plans;
  std::vector<Problem> problems;
  gis::GeosComparison cmp;
  bool ok = false;
  std::string message;  // summary + input WKT when not ok
};

/// Runs build_ground_plans (single thread unless threads given) and compares with GEOS UnaryUnion;
/// also checks our own promises: outer CCW, holes CW, members non-empty and ascending.
UnionCheck run_and_compare(const std::vector<Footprint>& fps, int threads = 1, double rel_tol = 1e-9);

/// WKT of all footprints (a MULTIPOLYGON-ish list, one per line) for failure messages.
std::string describe(const std::vector<Footprint>& fps);

}  // namespace groundplan::testing

// SPDX-License-Identifier: MIT
#pragma once
// Helpers for the union engine's tests: footprints from WKT, the engine run against GEOS.
#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <cstdint>
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
  bool geos_self_inconsistent = false;  // GEOS's union of its own result differed: that was used
  bool geos_symdiff_implausible = false;  // counts, areas, validity agree but GEOS's symmetric difference
                                          // did not: decided by sampling instead
  bool counts_match = false;
  /// Counts differ from GEOS's exact union, every difference a gap, neck or hole narrower than the snap
  /// pitch (GeosComparison::below_pitch), all else matching: features narrower than the pitch
  /// collapsed, as issue 20 asks. Strict accepts that (GeosComparison::matches); it is counted here.
  bool collapsed_below_pitch = false;
  std::string message;  // summary + input WKT when not ok
};

enum class Oracle {
  Strict,       // DESIGN.md: area within rel_tol, same numbers of polygons and holes, valid, no overlaps
  AreaAndValid, // only area within rel_tol and every plan valid: for inputs whose features are far
                // below one ulp, where GEOS's snapping and relate are not exact (see the property test)
};

/// Runs build_ground_plans (single thread unless threads given) and compares with GEOS UnaryUnion;
/// also checks our own promises: outer CCW, holes CW, members non-empty. When GEOS's result is not
/// a fixed point of GEOS's own union (it returned polygons sharing edges), that union is the reference.
/// `reference`, when given, is GEOS's union computed elsewhere (of an exact copy of `fps` on a lattice,
/// brought back to metres: tests/property/self_crossing_property_test.cpp) and is used instead.
UnionCheck run_and_compare(const std::vector<Footprint>& fps, int threads = 1, double rel_tol = 1e-9,
                           Oracle oracle = Oracle::Strict, const std::vector<GroundPlan>* reference = nullptr);

/// run_and_compare's checks of plans already computed (`plans`, `problems`: build_ground_plans's answer for `fps`).
UnionCheck compare_union(const std::vector<Footprint>& fps, std::vector<GroundPlan> plans, std::vector<Problem> problems,
                         double rel_tol = 1e-9, Oracle oracle = Oracle::Strict,
                         const std::vector<GroundPlan>* reference = nullptr);

/// Random points (seeded) where membership in the plans and in the union of the footprints (each
/// polygon by the even-odd rule) differ: an oracle independent of GEOS. Orientation in long double
/// on random points (a point exactly on a boundary has probability zero).
int sampling_disagreements(const std::vector<Footprint>& fps, const std::vector<GroundPlan>& plans, int n,
                           std::uint64_t seed);

/// WKT of all footprints (a MULTIPOLYGON-ish list, one per line) for failure messages.
std::string describe(const std::vector<Footprint>& fps);

}  // namespace groundplan::testing

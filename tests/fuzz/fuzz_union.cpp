// SPDX-License-Identifier: MIT
// The union engine on random polygon sets decoded from the fuzz bytes (issue 8), checked against
// GEOS UnaryUnion (gis/geosref compare_with_geos):
//   - always: every footprint a member of a plan or named by a union-stage Problem (nothing lost), no
//     exception but groundplan::Error;
//   - for every input, valid or not (issue 20, snap rounding): every plan valid by GEOS, no two plans
//     overlapping, no ROUNDING_INVALID, no near-touching output vertices (tests/support/near_touch.h);
//   - when every input polygon is valid by GEOS: the areas agree within 1e-6 (relative).
// Polygon and hole counts are reported (stderr, first few), not asserted: on near-degenerate input
// GEOS itself may be the odd one out (it snaps; we are exact).
//
// Decoding: byte 0 picks the coordinate mode (small integer grid: shared vertices, collinear edges,
// touching; a fine grid at a large offset; half-integers), then per footprint one byte of vertex count
// and a hole flag, and two bytes per vertex.
#include "fuzz_entry.h"
#include "fuzz_polygons.h"
#include "near_touch.h"

#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <geos_c.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

namespace {

bool polygon_valid_geos(GEOSContextHandle_t h, const groundplan::Polygon& poly) {
  auto ring = [&](const groundplan::Ring& r) -> GEOSGeometry* {
    GEOSCoordSequence* cs = GEOSCoordSeq_create_r(h, static_cast<unsigned>(r.size() + 1), 2);
    for (std::size_t i = 0; i <= r.size(); ++i) {
      GEOSCoordSeq_setX_r(h, cs, static_cast<unsigned>(i), r[i % r.size()].x);
      GEOSCoordSeq_setY_r(h, cs, static_cast<unsigned>(i), r[i % r.size()].y);
    }
    return GEOSGeom_createLinearRing_r(h, cs);
  };
  GEOSGeometry* shell = ring(poly.outer);
  std::vector<GEOSGeometry*> holes;
  for (const auto& r : poly.holes) holes.push_back(ring(r));
  GEOSGeometry* g = shell ? GEOSGeom_createPolygon_r(h, shell, holes.data(), static_cast<unsigned>(holes.size()))
                          : nullptr;
  const bool ok = g && GEOSisValid_r(h, g) == 1;
  if (g) GEOSGeom_destroy_r(h, g);
  return ok;
}

}  // namespace

GROUNDPLAN_FUZZ_TARGET(union) {
  using namespace groundplan;
  std::vector<Footprint> fps = fuzz::decode_footprints(data, size);
  if (fps.empty()) return 0;

  std::vector<Problem> problems;
  std::vector<GroundPlan> plans;
  UnionParams params;
  params.device = Device::Cpu;
  try {
    plans = build_ground_plans(fps, params, problems);
  } catch (const Error& e) {
    return 0;  // a refusal with a message is an answer (counted by the caller's log, not a finding)
  }

  // Nothing lost.
  std::vector<bool> member(fps.size(), false);
  for (const GroundPlan& gp : plans)
    for (std::uint32_t m : gp.members) {
      if (m >= fps.size()) groundplan_fuzz_fail("union", "a plan member index is out of range");
      member[m] = true;
    }
  std::set<std::string> union_problem;
  for (const Problem& p : problems)
    if (p.stage == "union") union_problem.insert(p.source_id);
  for (std::size_t i = 0; i < fps.size(); ++i)
    if (!member[i] && !union_problem.count(fps[i].source_id))
      groundplan_fuzz_fail("union", ("footprint " + fps[i].source_id + " is in no plan and has no union problem").c_str());

  const gis::GeosComparison c = gis::compare_with_geos(fps, plans);

  GEOSContextHandle_t h = GEOS_init_r();
  bool inputs_valid = true;
  for (const Footprint& f : fps)
    for (const Polygon& p : f.polygons) inputs_valid = inputs_valid && polygon_valid_geos(h, p);
  GEOS_finish_r(h);
  // Invalid or overlapping plans: a failure for every input (issue 20: where rounded output would be
  // invalid or overlapping, snap rounding makes it valid and disjoint by construction).
  if (c.invalid_ours) groundplan_fuzz_fail("union", ("invalid plan: " + c.first_invalid_reason).c_str());
  if (c.overlapping_ours) groundplan_fuzz_fail("union", ("two plans overlap: " + c.summary()).c_str());
  // Near-touching output (vertices closer than a few ulps that are not one vertex): a failure for every
  // input (issue 20: vertices closer than the snap pitch are one vertex).
  const groundplan::testing::NearTouch nt = groundplan::testing::near_touch(plans);
  if (nt.pairs) groundplan_fuzz_fail("union", ("near-touching output: " + nt.first).c_str());
  for (const Problem& p : problems)
    if (p.code == "ROUNDING_INVALID") groundplan_fuzz_fail("union", ("ROUNDING_INVALID: " + p.reason).c_str());
  const double tol = 1e-6 * std::max(c.area_geos, 1.0);
  if (inputs_valid && std::fabs(c.area_ours - c.area_geos) > tol)
    groundplan_fuzz_fail("union", ("area differs from GEOS on valid input: " + c.summary()).c_str());
  static int reported = 0;
  if ((!inputs_valid && std::fabs(c.area_ours - c.area_geos) > tol) || c.polygons_ours != c.polygons_geos ||
      c.holes_ours != c.holes_geos) {
    if (reported++ < 5) std::fprintf(stderr, "groundplan fuzz union: disagreement with GEOS (reported, not a failure): %s\n",
                                     c.summary().c_str());
  }
  return 0;
}

// SPDX-License-Identifier: MIT
// The union engine on random polygon sets decoded from the fuzz bytes (issue 8), checked against
// GEOS UnaryUnion (gis/geosref compare_with_geos):
//   - always: every plan valid by GEOS, no two plans overlapping, every footprint a member of a plan
//     or named by a union-stage Problem (nothing lost), no exception but groundplan::Error;
//   - when every input polygon is valid by GEOS: the areas agree within 1e-6 (relative).
// Polygon and hole counts are reported (stderr, first few), not asserted: on near-degenerate input
// GEOS itself may be the odd one out (it snaps; we are exact).
//
// Decoding: byte 0 picks the coordinate mode (small integer grid: shared vertices, collinear edges,
// touching; a fine grid at a large offset; half-integers), then per footprint one byte of vertex count
// and a hole flag, and two bytes per vertex.
#include "fuzz_entry.h"

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

struct Decoder {
  const std::uint8_t* p;
  const std::uint8_t* end;
  bool more() const { return p < end; }
  std::uint8_t byte() { return p < end ? *p++ : 0; }
};

double coord(std::uint8_t v, int mode, bool is_x) {
  switch (mode) {
    case 0: return static_cast<double>(v % 16);                             // tiny grid: degeneracies
    case 1: return (is_x ? 500000.0 : 5400000.0) + static_cast<double>(v) * 0.125;  // offset, dyadic
    case 2: return static_cast<double>(v) * 0.5;
    default: return static_cast<double>(v) / 7.0;                           // inexact
  }
}

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
  Decoder d{data, data + size};
  const int mode = d.byte() % 4;
  std::vector<Footprint> fps;
  while (d.more() && fps.size() < 12) {
    const std::uint8_t head = d.byte();
    const std::size_t n = 3 + head % 14;
    const bool with_hole = head & 0x80;
    Footprint f;
    f.source_id = "f" + std::to_string(fps.size());
    Polygon poly;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint8_t x = d.byte(), y = d.byte();
      poly.outer.push_back({coord(x, mode, true), coord(y, mode, false)});
    }
    if (with_hole)
      for (std::size_t i = 0; i < 3 + (head >> 4) % 4; ++i) {
        const std::uint8_t x = d.byte(), y = d.byte();
        if (poly.holes.empty()) poly.holes.emplace_back();
        poly.holes.back().push_back({coord(x, mode, true), coord(y, mode, false)});
      }
    f.polygons.push_back(std::move(poly));
    fps.push_back(std::move(f));
  }
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
  if (c.invalid_ours) groundplan_fuzz_fail("union", ("invalid plan: " + c.first_invalid_reason).c_str());
  if (c.overlapping_ours) groundplan_fuzz_fail("union", "two plans overlap");

  GEOSContextHandle_t h = GEOS_init_r();
  bool inputs_valid = true;
  for (const Footprint& f : fps)
    for (const Polygon& p : f.polygons) inputs_valid = inputs_valid && polygon_valid_geos(h, p);
  GEOS_finish_r(h);
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

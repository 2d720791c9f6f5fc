// SPDX-License-Identifier: MIT
#include "union_test_util.h"

#include <algorithm>
#include <sstream>

namespace groundplan::testing {

Footprint footprint_from_wkt(const std::string& wkt, const std::string& id) {
  Footprint f;
  f.polygons = gis::polygons_from_wkt(wkt);
  f.source_id = id;
  return f;
}

std::vector<Footprint> footprints_from_wkt(const std::vector<std::string>& wkts) {
  std::vector<Footprint> out;
  for (std::size_t i = 0; i < wkts.size(); ++i) out.push_back(footprint_from_wkt(wkts[i], "f" + std::to_string(i)));
  return out;
}

namespace {
long double area2(const Ring& r) {
  long double s = 0;
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point2& a = r[i];
    const Point2& b = r[(i + 1) % n];
    s += static_cast<long double>(a.x) * b.y - static_cast<long double>(b.x) * a.y;
  }
  return s;
}
}  // namespace

std::string describe(const std::vector<Footprint>& fps) {
  std::ostringstream s;
  for (const Footprint& f : fps)
    for (const Polygon& p : f.polygons) s << "  \"" << gis::to_wkt(p) << "\",\n";
  return s.str();
}

UnionCheck run_and_compare(const std::vector<Footprint>& fps, int threads, double rel_tol, Oracle oracle) {
  UnionCheck c;
  UnionParams params;
  params.threads = threads;
  std::ostringstream msg;
  try {
    c.plans = build_ground_plans(fps, params, c.problems);
  } catch (const std::exception& e) {
    c.ok = false;
    c.message = std::string("exception: ") + e.what() + "\ninput:\n" + describe(fps);
    return c;
  }
  std::vector<GroundPlan> ref = gis::geos_union(fps);
  {
    std::vector<Footprint> again(1);
    for (const GroundPlan& g : ref) again[0].polygons.push_back(g.polygon);
    std::vector<GroundPlan> ref2 = gis::geos_union(again);
    std::size_t h1 = 0, h2 = 0;
    for (const GroundPlan& g : ref) h1 += g.polygon.holes.size();
    for (const GroundPlan& g : ref2) h2 += g.polygon.holes.size();
    if (ref2.size() != ref.size() || h1 != h2) {
      c.geos_self_inconsistent = true;
      ref = std::move(ref2);
    }
  }
  c.cmp = gis::compare_with_geos(fps, c.plans, &ref);
  c.counts_match = c.cmp.polygons_ours == c.cmp.polygons_geos && c.cmp.holes_ours == c.cmp.holes_geos;
  if (oracle == Oracle::Strict) {
    c.ok = c.cmp.matches(rel_tol);
  } else {
    c.ok = c.cmp.symdiff_area <= rel_tol * std::max(c.cmp.area_geos, c.cmp.area_ours) && c.cmp.invalid_ours == 0;
  }
  msg << c.cmp.summary();
  if (c.geos_self_inconsistent) msg << " (GEOS result was not a fixed point of GEOS union: re-unioned)";
  for (const GroundPlan& g : c.plans) {
    if (area2(g.polygon.outer) <= 0) {
      c.ok = false;
      msg << "; outer ring not CCW";
    }
    for (const Ring& h : g.polygon.holes)
      if (area2(h) >= 0) {
        c.ok = false;
        msg << "; hole not CW";
      }
    if (g.members.empty()) {
      c.ok = false;
      msg << "; plan without members";
    }
  }
  for (const Problem& p : c.problems)
    if (p.code != "NO_AREA") {
      c.ok = false;
      msg << "; problem " << p.code << ": " << p.reason;
    }
  if (!c.ok) {
    msg << "\ninput:\n" << describe(fps) << "ours:\n";
    for (const GroundPlan& g : c.plans) msg << "  " << gis::to_wkt(g.polygon) << "\n";
  }
  c.message = msg.str();
  return c;
}

}  // namespace groundplan::testing

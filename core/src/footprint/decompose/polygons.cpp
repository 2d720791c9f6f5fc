// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 7, loops to polygons.
//
//  7. Loops projected to 2D: counter-clockwise = outer ring, clockwise = hole; each hole goes to the
//     smallest outer ring of its own part that contains it. Parts whose outside cannot be told use
//     nesting depth instead.
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

bool Decomposer::loop_contains(const Workspace::Loop& outer, const Workspace::Loop& h) const {
  if (h.minx < outer.minx || h.maxx > outer.maxx || h.miny < outer.miny || h.maxy > outer.maxy) return false;
  // Probe: midpoint of the hole's longest edge (its vertices may touch the outer ring).
  const Point2* r = ws_.loop_pts.data() + h.first;
  std::size_t best = 0;
  double bl = -1;
  for (std::size_t i = 0; i < h.count; ++i) {
    const Point2 &p = r[i], &q = r[i + 1 < h.count ? i + 1 : 0];
    const double l = (q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y);
    if (l > bl) bl = l, best = i;
  }
  const Point2 &p = r[best], &q = r[best + 1 < h.count ? best + 1 : 0];
  return inside(ws_.loop_pts.data() + outer.first, outer.count, Point2{(p.x + q.x) / 2, (p.y + q.y) / 2});
}

void Decomposer::make_polygons(std::vector<Polygon>& out) {
  auto& loops = ws_.loops;
  // Parts whose outside is unknown: outer or hole by nesting depth among that part's loops.
  if (stats_->unoriented_components > 0) {
    for (std::size_t i = 0; i < loops.size(); ++i) {
      if (ws_.comp_sign[loops[i].comp] != 0) continue;
      std::size_t depth = 0;
      Workspace::Loop li = loops[i];
      if (li.area < 0) li.area = -li.area;
      for (std::size_t j = 0; j < loops.size(); ++j)
        if (j != i && loops[j].comp == loops[i].comp && std::fabs(loops[j].area) > li.area && loop_contains(loops[j], loops[i]))
          ++depth;
      const bool want_ccw = depth % 2 == 0;
      if ((loops[i].area > 0) != want_ccw) {
        std::reverse(ws_.loop_pts.begin() + loops[i].first, ws_.loop_pts.begin() + loops[i].first + loops[i].count);
        loops[i].area = -loops[i].area;
      }
    }
  }
  auto& poly_of_loop = ws_.poly_of_loop;
  poly_of_loop.assign(loops.size(), -1);
  auto ring = [&](const Workspace::Loop& L) {
    Ring r(L.count);
    const Point2* s = ws_.loop_pts.data() + L.first;
    for (std::size_t i = 0; i < L.count; ++i) r[i] = Point2{s[i].x + o_.x, s[i].y + o_.y};
    return r;
  };
  for (std::size_t i = 0; i < loops.size(); ++i) {
    if (loops[i].area <= 0) continue;
    poly_of_loop[i] = static_cast<std::int32_t>(out.size());
    out.push_back(Polygon{ring(loops[i]), {}});
  }
  for (std::size_t i = 0; i < loops.size(); ++i) {
    if (loops[i].area > 0) continue;
    const Workspace::Loop& h = loops[i];
    // The smallest outer ring containing the hole, one of its own part if any does.
    std::int32_t best = -1;
    double best_area = std::numeric_limits<double>::infinity();
    bool best_same = false;
    for (std::size_t j = 0; j < loops.size(); ++j) {
      if (poly_of_loop[j] < 0 || loops[j].area <= -h.area) continue;
      const bool same = loops[j].comp == h.comp;
      const bool better = best < 0 || (same && !best_same) || (same == best_same && loops[j].area < best_area);
      if (!better || !loop_contains(loops[j], h)) continue;
      best = poly_of_loop[j];
      best_area = loops[j].area;
      best_same = same;
    }
    if (best < 0) {
      ++stats_->dropped_loops;
      continue;
    }
    out[best].holes.push_back(ring(h));
    ++stats_->holes;
  }
}

/// True when a tenth or more of the lower boundary (by plan length) lies in open chains outside
/// every outer loop and no higher than the loops reach: then the loops miss part of where the
/// building stands. Open chains inside a loop (a part standing on another) or above every loop
/// (a balcony, a canopy: floating slabs are local minima too, but not ground) do not count.
bool Decomposer::open_outside_loops() const {
  if (ws_.open_edges.empty()) return false;
  double zmax = -std::numeric_limits<double>::infinity();
  for (const Workspace::Loop& L : ws_.loops) zmax = std::max(zmax, L.zmax);
  double outside = 0;
  for (std::uint32_t e : ws_.open_edges) {
    const V3 &a = ws_.wpos[ws_.cand[e].from], &b = ws_.wpos[ws_.cand[e].to];
    if (std::min(a.z, b.z) > zmax + tol_) continue;
    const Point2 mid{(a.x + b.x) / 2, (a.y + b.y) / 2};
    bool in = false;
    for (const Workspace::Loop& L : ws_.loops) {
      if (L.area <= 0 || mid.x < L.minx || mid.x > L.maxx || mid.y < L.miny || mid.y > L.maxy) continue;
      if ((in = inside(ws_.loop_pts.data() + L.first, L.count, mid))) break;
    }
    if (!in) outside += plan_length(ws_.cand[e]);
  }
  stats_->lower_boundary_m = lower_boundary_len_;
  stats_->open_outside_m = outside;
  return outside >= 0.1 * lower_boundary_len_;
}

}  // namespace groundplan::footprint::detail

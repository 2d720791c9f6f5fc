// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). The last step: a footprint never overlaps
// itself (issue 21). Loops of different parts may overlap (a part's loop inside another's, parts set
// side by side whose walls overlap); a MultiPolygon whose parts overlap is invalid in OGC and counts
// the overlap twice, so the polygons of one footprint are united here with the project's exact union
// engine (core/src/union, not GEOS), as the shadow is.
#include "footprint/decompose/decomposer.h"

#include <groundplan/ground_plans.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace groundplan::footprint::detail {

bool unite_polygons(std::vector<Polygon>& polys, double min_ring_m2) {
  Footprint fp;
  fp.polygons = std::move(polys);
  polys.clear();
  double minx = std::numeric_limits<double>::infinity(), maxx = -minx, miny = minx, maxy = -minx;
  for (const Polygon& p : fp.polygons)
    for (const Point2& q : p.outer)
      minx = std::min(minx, q.x), maxx = std::max(maxx, q.x), miny = std::min(miny, q.y), maxy = std::max(maxy, q.y);
  UnionParams up;
  up.threads = 1;  // decomposition runs on the caller's thread (the pipeline parallelises buildings)
  up.device = Device::Cpu;
  // One footprint is one block at any resolution, and the raster only finds blocks (exactness never
  // depends on it): pixels as wide as the footprint mark a handful, where 1/256 of it marked some
  // 66,000 and sorting them was most of the union's cost (Macky's plan faces).
  up.resolution_m = std::max({maxx - minx, maxy - miny, 1e-6});
  std::vector<Problem> problems;
  std::vector<GroundPlan> plans;
  try {
    plans = build_ground_plans(std::vector<Footprint>{fp}, up, problems);
  } catch (const std::exception&) {
    plans.clear();
  }
  if (plans.empty()) {
    polys = std::move(fp.polygons);
    return false;
  }
  for (GroundPlan& g : plans) {
    if (std::fabs(ring_area(g.polygon.outer)) < min_ring_m2) continue;
    auto& h = g.polygon.holes;
    h.erase(std::remove_if(h.begin(), h.end(), [&](const Ring& r) { return std::fabs(ring_area(r)) < min_ring_m2; }), h.end());
    polys.push_back(std::move(g.polygon));
  }
  return true;
}

void Decomposer::unite_loops(std::vector<Polygon>& polys) {
  if (polys.size() < 2) return;
  // Only when two outer rings' boxes meet: most buildings have one loop, or loops far apart.
  struct Box {
    double minx, miny, maxx, maxy;
  };
  std::vector<Box> boxes;
  boxes.reserve(polys.size());
  for (const Polygon& p : polys) {
    Box b{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (const Point2& q : p.outer) b.minx = std::min(b.minx, q.x), b.maxx = std::max(b.maxx, q.x), b.miny = std::min(b.miny, q.y), b.maxy = std::max(b.maxy, q.y);
    boxes.push_back(b);
  }
  bool meet = false;
  for (std::size_t i = 0; i < boxes.size() && !meet; ++i)
    for (std::size_t j = i + 1; j < boxes.size() && !meet; ++j)
      meet = boxes[i].minx <= boxes[j].maxx && boxes[j].minx <= boxes[i].maxx && boxes[i].miny <= boxes[j].maxy &&
             boxes[j].miny <= boxes[i].maxy;
  if (!meet) return;
  if (unite_polygons(polys, p_.min_loop_area_m2)) stats_->united = true;
}

}  // namespace groundplan::footprint::detail

// SPDX-License-Identifier: MIT
#include "near_touch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>

#include "robust/predicates.h"

namespace groundplan::testing {
namespace {

struct Seg {
  Point2 a, b;
};

double ulp_at(double m) { return std::nextafter(m, std::numeric_limits<double>::infinity()) - m; }

/// Distance from p to the interior of segment ab in long double (a hint of size; exactness comes from
/// orient); infinity where p projects onto an end or beyond (the vertex-vertex pass covers the ends).
long double interior_dist(const Point2& p, const Seg& s) {
  const long double dx = static_cast<long double>(s.b.x) - s.a.x, dy = static_cast<long double>(s.b.y) - s.a.y;
  const long double px = static_cast<long double>(p.x) - s.a.x, py = static_cast<long double>(p.y) - s.a.y;
  const long double len2 = dx * dx + dy * dy;
  const long double t = len2 > 0 ? (px * dx + py * dy) / len2 : 0;
  if (!(t > 0 && t < 1)) return std::numeric_limits<long double>::infinity();
  const long double ex = px - t * dx, ey = py - t * dy;
  return std::sqrt(ex * ex + ey * ey);
}

std::string where(const Point2& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.17g %.17g)", p.x, p.y);
  return buf;
}

}  // namespace

NearTouch near_touch(const std::vector<GroundPlan>& plans, double ulps, const std::vector<Footprint>* input) {
  auto less = [](const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); };
  std::vector<Point2> in;  // the input vertices, sorted, for "did the union compute this point?"
  if (input)
    for (const Footprint& f : *input)
      for (const Polygon& poly : f.polygons) {
        in.insert(in.end(), poly.outer.begin(), poly.outer.end());
        for (const Ring& h : poly.holes) in.insert(in.end(), h.begin(), h.end());
      }
  std::sort(in.begin(), in.end(), less);
  auto computed = [&](std::initializer_list<Point2> pts) {
    if (!input) return false;
    for (const Point2& p : pts)
      if (!std::binary_search(in.begin(), in.end(), p, less)) return true;
    return false;
  };
  std::vector<Point2> pts;
  std::vector<Seg> segs;
  for (const GroundPlan& g : plans) {
    auto ring = [&](const Ring& r) {
      for (std::size_t i = 0; i < r.size(); ++i) {
        pts.push_back(r[i]);
        segs.push_back({r[i], r[(i + 1) % r.size()]});
      }
    };
    ring(g.polygon.outer);
    for (const Ring& h : g.polygon.holes) ring(h);
  }
  NearTouch out;
  auto found = [&](const std::string& what, bool by_union) {
    if (out.pairs++ == 0) out.first = what;
    if (by_union && out.computed++ == 0) out.first_computed = what;
  };
  auto tol = [&](double m) { return ulps * ulp_at(m); };
  // vertex-vertex: sweep by x
  std::sort(pts.begin(), pts.end(), less);
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j) {
      const double m = std::max({std::fabs(pts[i].x), std::fabs(pts[i].y), std::fabs(pts[j].x), std::fabs(pts[j].y)});
      const double t = tol(m);
      if (pts[j].x - pts[i].x > t) break;
      if (std::fabs(pts[j].y - pts[i].y) <= t)
        found("vertices " + where(pts[i]) + " and " + where(pts[j]) + " are distinct but within " +
              std::to_string(ulps) + " ulps",
              computed({pts[i], pts[j]}));
    }
  // vertex-edge: edges sorted by their smaller x; a vertex looks at edges starting up to the longest
  // edge's x extent to its left
  std::sort(segs.begin(), segs.end(), [](const Seg& a, const Seg& b) { return std::min(a.a.x, a.b.x) < std::min(b.a.x, b.b.x); });
  double max_w = 0;
  for (const Seg& s : segs) max_w = std::max(max_w, std::fabs(s.b.x - s.a.x));
  for (const Point2& p : pts) {
    const double m = std::max(std::fabs(p.x), std::fabs(p.y));
    const double t = tol(m);
    auto it = std::lower_bound(segs.begin(), segs.end(), p.x - max_w - t,
                               [](const Seg& s, double x) { return std::min(s.a.x, s.b.x) < x; });
    for (; it != segs.end() && std::min(it->a.x, it->b.x) <= p.x + t; ++it) {
      const Seg& s = *it;
      if (p == s.a || p == s.b) continue;
      if (std::max(s.a.x, s.b.x) < p.x - t || std::min(s.a.y, s.b.y) > p.y + t || std::max(s.a.y, s.b.y) < p.y - t)
        continue;
      if (robust::orient(s.a, s.b, p) == 0) continue;  // exactly on the line: exact contact, or beyond the ends
      const double mm = std::max({m, std::fabs(s.a.x), std::fabs(s.a.y), std::fabs(s.b.x), std::fabs(s.b.y)});
      if (interior_dist(p, s) <= tol(mm))
        found("vertex " + where(p) + " is within " + std::to_string(ulps) + " ulps of edge " + where(s.a) + "-" +
              where(s.b) + " but not on it",
              computed({p, s.a, s.b}));
    }
  }
  return out;
}

}  // namespace groundplan::testing

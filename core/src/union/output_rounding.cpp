// SPDX-License-Identifier: MIT
// Exact measures and checks of output rings on their doubles: area, orientation, point location,
// and the validity check that guards snap-rounded plans (snap_round.h does the rounding).
#include "union/output_rounding.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <utility>

#include "robust/predicates.h"
#include "union/block_types.h"
#include "union/box_grid.h"

namespace groundplan::detail {

using robust::orient;

/// Twice the signed area, about the ring's first vertex: at UTM magnitudes (1e6..1e7 m) the shoelace
/// on absolute coordinates loses ~1e-7 m² even in long double; differences to a vertex of the ring
/// are exact (same binade scale) and keep the area_m2 field within ~1e-13 relative.
long double signed_area2(const std::vector<Point2>& r) {
  if (r.empty()) return 0;
  const long double x0 = r[0].x, y0 = r[0].y;
  long double s = 0;
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point2& a = r[i];
    const Point2& b = r[(i + 1) % n];
    s += (a.x - x0) * (b.y - y0) - (b.x - x0) * (a.y - y0);
  }
  return s;
}

/// Orientation of a ring: the sign of its area (long double, relative to its first vertex, so
/// that 1e7 coordinates lose nothing) where that sign is certain, else exactly from its
/// lowest-leftmost vertex (which is convex in a simple ring). The area decides first because a
/// ring whose sub-ulp sliver was twisted by rounding can be wrong at that one vertex.
int ring_orientation(const std::vector<Point2>& r) {
  const std::size_t n = r.size();
  long double s = 0, mag = 0;
  const Point2& o = r[0];
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const long double ax = static_cast<long double>(r[i].x) - o.x, ay = static_cast<long double>(r[i].y) - o.y;
    const long double bx = static_cast<long double>(r[i + 1].x) - o.x, by = static_cast<long double>(r[i + 1].y) - o.y;
    const long double t1 = ax * by, t2 = bx * ay;
    s += t1 - t2;
    mag += std::fabs(t1) + std::fabs(t2);
  }
  if (std::fabs(s) > mag * 1e-16L * static_cast<long double>(n + 4)) return s > 0 ? 1 : -1;
  std::size_t k = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (r[i].y < r[k].y || (r[i].y == r[k].y && r[i].x < r[k].x)) k = i;
  return orient(r[(k + n - 1) % n], r[k], r[(k + 1) % n]);
}

/// +1 strictly inside, -1 strictly outside, 0 on the boundary (exact, on the rounded ring).
int point_in_ring(const Point2& p, const std::vector<Point2>& r) {
  bool odd = false;
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point2& a = r[i];
    const Point2& b = r[(i + 1) % n];
    if (std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
        p.y <= std::max(a.y, b.y) && orient(a, b, p) == 0)
      return 0;
    const bool up = a.y < b.y;
    const Point2& lo = up ? a : b;
    const Point2& hi = up ? b : a;
    if (lo.y <= p.y && p.y < hi.y && orient(lo, hi, p) > 0) odd = !odd;
  }
  return odd ? 1 : -1;
}

namespace {

/// One ring edge's box, for the sweep over edges in order of their least x.
struct Seg {
  double minx, maxx, miny, maxy;
  std::size_t ring, edge;
};

/// Every edge of every ring (ring r's edge i runs from vertex i to i + 1, cyclically), by least x.
std::vector<Seg> edges_by_min_x(const std::vector<std::vector<Point2>*>& rings) {
  std::vector<Seg> segs;
  for (std::size_t r = 0; r < rings.size(); ++r) {
    const auto& R = *rings[r];
    for (std::size_t i = 0, n = R.size(); i < n; ++i) {
      const Point2& a = R[i];
      const Point2& b = R[(i + 1) % n];
      segs.push_back({std::min(a.x, b.x), std::max(a.x, b.x), std::min(a.y, b.y), std::max(a.y, b.y), r, i});
    }
  }
  std::sort(segs.begin(), segs.end(), [](const Seg& x, const Seg& y) { return x.minx < y.minx; });
  return segs;
}

}  // namespace

/// Validity of one plan on its rounded coordinates, exactly (robust predicates on the doubles):
/// OGC says no two ring edges may cross or overlap, and a ring may not touch itself; rings of one
/// plan may touch at points. Returns false and the ring/vertex of a conflict if invalid.
bool find_conflict(const std::vector<std::vector<Point2>*>& rings, Conflict& c) {
  const std::vector<Seg> segs = edges_by_min_x(rings);
  auto pt = [&](std::size_t r, std::size_t i) -> const Point2& { return (*rings[r])[i % rings[r]->size()]; };
  auto on_seg = [](const Point2& a, const Point2& b, const Point2& p) {  // p on closed segment, collinear known
    return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
           p.y <= std::max(a.y, b.y);
  };
  for (std::size_t i = 0; i < segs.size(); ++i) {
    for (std::size_t j = i + 1; j < segs.size() && segs[j].minx <= segs[i].maxx; ++j) {
      const Seg& s = segs[i];
      const Seg& t = segs[j];
      if (t.miny > s.maxy || s.miny > t.maxy) continue;
      const std::size_t n = rings[s.ring]->size();
      const bool same = s.ring == t.ring;
      const bool adjacent = same && ((s.edge + 1) % n == t.edge || (t.edge + 1) % n == s.edge);
      const Point2 &p1 = pt(s.ring, s.edge), &p2 = pt(s.ring, s.edge + 1);
      const Point2 &q1 = pt(t.ring, t.edge), &q2 = pt(t.ring, t.edge + 1);
      const int o1 = orient(p1, p2, q1), o2 = orient(p1, p2, q2), o3 = orient(q1, q2, p1), o4 = orient(q1, q2, p2);
      bool bad = false;
      if (o1 * o2 < 0 && o3 * o4 < 0) {
        bad = true;  // proper crossing
      } else if (o1 == 0 && o2 == 0) {
        // collinear: overlap of positive length is invalid (also for adjacent edges: a spike)
        const bool x = std::fabs(p2.x - p1.x) >= std::fabs(p2.y - p1.y);
        auto k = [&](const Point2& p) { return x ? p.x : p.y; };
        const double lo = std::max(std::min(k(p1), k(p2)), std::min(k(q1), k(q2)));
        const double hi = std::min(std::max(k(p1), k(p2)), std::max(k(q1), k(q2)));
        bad = lo < hi;
      } else if (same && !adjacent) {
        // a ring touching itself: a vertex on another edge of the same ring
        bad = (o1 == 0 && on_seg(p1, p2, q1)) || (o2 == 0 && on_seg(p1, p2, q2)) || (o3 == 0 && on_seg(q1, q2, p1)) ||
              (o4 == 0 && on_seg(q1, q2, p2));
      }
      if (bad) {
        c = {s.ring, s.edge, t.ring, t.edge};
        return true;
      }
    }
  }
  return false;
}

bool touch_cycle(const std::vector<std::vector<Point2>*>& rings) {
  // only a cycle through a hole counts: without a hole there is nothing to look for (most groups)
  std::vector<char> hole(rings.size(), 0);
  bool any_hole = false;
  for (std::size_t r = 0; r < rings.size(); ++r)
    any_hole |= hole[r] = rings[r]->size() >= 3 && ring_orientation(*rings[r]) < 0;
  if (!any_hole) return false;
  // the graph of rings and touch points, each point one node; an incidence (ring, point) joining two
  // nodes already connected closes a cycle
  const std::vector<Seg> segs = edges_by_min_x(rings);
  auto pt = [&](std::size_t r, std::size_t i) -> const Point2& { return (*rings[r])[i % rings[r]->size()]; };
  // touches: (point, ring) for both rings of every touch; collected first, then deduplicated
  std::vector<std::pair<std::pair<double, double>, std::size_t>> inc;
  auto on_closed = [](const Point2& a, const Point2& b, const Point2& p) {
    return orient(a, b, p) == 0 && std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) &&
           std::min(a.y, b.y) <= p.y && p.y <= std::max(a.y, b.y);
  };
  for (std::size_t i = 0; i < segs.size(); ++i) {
    for (std::size_t j = i + 1; j < segs.size() && segs[j].minx <= segs[i].maxx; ++j) {
      const Seg& s = segs[i];
      const Seg& t = segs[j];
      if (s.ring == t.ring || t.miny > s.maxy || s.miny > t.maxy) continue;
      const Point2 &p1 = pt(s.ring, s.edge), &p2 = pt(s.ring, s.edge + 1);
      const Point2 &q1 = pt(t.ring, t.edge), &q2 = pt(t.ring, t.edge + 1);
      for (const Point2* q : {&q1, &q2})
        if (on_closed(p1, p2, *q)) {
          inc.push_back({{q->x, q->y}, s.ring});
          inc.push_back({{q->x, q->y}, t.ring});
        }
      for (const Point2* p : {&p1, &p2})
        if (on_closed(q1, q2, *p)) {
          inc.push_back({{p->x, p->y}, s.ring});
          inc.push_back({{p->x, p->y}, t.ring});
        }
    }
  }
  if (inc.empty()) return false;
  std::sort(inc.begin(), inc.end());
  inc.erase(std::unique(inc.begin(), inc.end()), inc.end());
  std::vector<std::size_t> parent(rings.size() + inc.size());
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  auto find = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  hole.resize(parent.size(), 0);
  std::vector<char> cycle(parent.size(), 0);
  std::size_t node = rings.size();
  for (std::size_t k = 0; k < inc.size(); ++k) {
    if (k > 0 && inc[k].first != inc[k - 1].first) ++node;
    const std::size_t a = find(node), b = find(inc[k].second);
    if (a == b) {
      cycle[a] = 1;
      continue;
    }
    parent[a] = b;
    hole[b] |= hole[a];
    cycle[b] |= cycle[a];
  }
  for (std::size_t x = 0; x < parent.size(); ++x)
    if (parent[x] == x && hole[x] && cycle[x]) return true;
  return false;
}

std::vector<char> nesting_flips(const std::vector<std::vector<Point2>>& rings, const std::vector<char>& subject) {
  const std::size_t n = rings.size();
  std::vector<char> flip(n, 0);
  if (std::find(subject.begin(), subject.end(), 1) == subject.end()) return flip;
  std::vector<Box> box(n);
  Box all;
  for (std::size_t i = 0; i < n; ++i) {
    for (const Point2& p : rings[i]) box[i].add(p);
    all.add({box[i].minx, box[i].miny});
    all.add({box[i].maxx, box[i].maxy});
  }
  auto within = [](const Box& in, const Box& out) {
    return out.minx <= in.minx && in.maxx <= out.maxx && out.miny <= in.miny && in.maxy <= out.maxy;
  };
  // +1 if ring s lies strictly inside ring q, -1 outside, 0 undecided (every vertex and edge midpoint on q)
  auto inside = [&](std::size_t s, std::size_t q) {
    const auto& S = rings[s];
    for (const Point2& p : S)
      if (const int l = point_in_ring(p, rings[q])) return l;
    for (std::size_t i = 0; i < S.size(); ++i) {
      const Point2& a = S[i];
      const Point2& b = S[(i + 1) % S.size()];
      if (const int l = point_in_ring({0.5 * a.x + 0.5 * b.x, 0.5 * a.y + 0.5 * b.y}, rings[q])) return l;
    }
    return 0;
  };
  auto check = [&](std::size_t s, auto&& candidates) {
    const int o = rings[s].size() >= 3 ? ring_orientation(rings[s]) : 0;
    if (o == 0) return;
    std::size_t count = 0;
    candidates([&](std::size_t q) {
      if (q != s && rings[q].size() >= 3 && within(box[s], box[q]) && inside(s, q) > 0) ++count;
    });
    flip[s] = (o > 0) == (count % 2 == 1);
  };
  if (n <= 64) {
    for (std::size_t s = 0; s < n; ++s)
      if (subject[s]) check(s, [&](auto&& f) { for (std::size_t q = 0; q < n; ++q) f(q); });
    return flip;
  }
  BoxGrid grid;
  grid.build(box, all, n);
  for (std::size_t s = 0; s < n; ++s)
    if (subject[s]) check(s, [&](auto&& f) { grid.query(box[s], [&](std::uint32_t q) { f(q); }); });
  return flip;
}

}  // namespace groundplan::detail

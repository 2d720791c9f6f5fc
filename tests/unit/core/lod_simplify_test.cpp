// SPDX-License-Identifier: MIT
// --simplify (issue 9): Douglas-Peucker that never lets rings cross, holes leave, plans overlap or
// touch points vanish. Validity is checked exactly here (robust::orient); GEOS checks the random
// cities in tests/unit/gis/lod_snap_simplify_geos_test.cpp.
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "robust/predicates.h"

namespace groundplan {
namespace {

using robust::orient;

GroundPlan plan(Ring outer, std::vector<Ring> holes = {}, std::vector<std::uint32_t> members = {0}) {
  GroundPlan p;
  p.polygon = {std::move(outer), std::move(holes)};
  p.members = std::move(members);
  p.area_m2 = polygon_area(p.polygon);
  return p;
}

/// Signed area (CCW positive), about the first vertex.
double signed_area(const Ring& r) {
  double s = 0;
  for (std::size_t i = 1; i + 1 < r.size(); ++i)
    s += (r[i].x - r[0].x) * (r[i + 1].y - r[0].y) - (r[i + 1].x - r[0].x) * (r[i].y - r[0].y);
  return s / 2;
}

bool on_segment(const Point2& p, const Point2& q, const Point2& r) {
  return orient(p, q, r) == 0 && std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) &&
         std::min(p.y, q.y) <= r.y && r.y <= std::max(p.y, q.y);
}

/// Segments meet other than at one common endpoint (where they must not overlap). Exact.
bool segments_clash(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const int shared = (a == c) + (a == d) + (b == c) + (b == d);
  if (shared >= 2) return true;
  if (shared == 1) {
    const Point2& s = (a == c || a == d) ? a : b;
    const Point2& u = s == a ? b : a;
    const Point2& w = (c == s) ? d : c;
    return on_segment(s, u, w) || on_segment(s, w, u);
  }
  const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 == 0 && o2 == 0) return on_segment(a, b, c) || on_segment(a, b, d) || on_segment(c, d, a) || on_segment(c, d, b);
  return o1 * o2 <= 0 && o3 * o4 <= 0;
}

/// +1 strictly inside ring r, 0 on it, -1 outside (exact).
int locate(const Point2& p, const Ring& r) {
  bool odd = false;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Point2& s = r[i];
    const Point2& t = r[(i + 1) % r.size()];
    const int o = orient(s, t, p);
    if (on_segment(s, t, p)) return 0;
    if ((s.y > p.y) != (t.y > p.y) && (o > 0) == (t.y > s.y)) odd = !odd;
  }
  return odd ? 1 : -1;
}

struct Edge {
  Point2 a, b;
  std::size_t ring;
  std::size_t index, size;
};

/// Every ring simple, no two rings crossing or sharing an edge, outer CCW, holes CW, holes inside
/// their shell, no two plans overlapping (no vertex of one strictly inside the other's shell but
/// outside its holes; with no crossings that is overlap). Brute force: small inputs only.
std::string validity_problem(const std::vector<GroundPlan>& plans) {
  std::vector<Edge> edges;
  std::vector<const Ring*> rings;
  for (const auto& p : plans) {
    rings.push_back(&p.polygon.outer);
    for (const auto& h : p.polygon.holes) rings.push_back(&h);
  }
  for (std::size_t r = 0; r < rings.size(); ++r) {
    if (rings[r]->size() < 3) return "ring " + std::to_string(r) + " has fewer than 3 vertices";
    for (std::size_t i = 0; i < rings[r]->size(); ++i)
      edges.push_back({(*rings[r])[i], (*rings[r])[(i + 1) % rings[r]->size()], r, i, rings[r]->size()});
  }
  for (std::size_t i = 0; i < edges.size(); ++i)
    for (std::size_t j = i + 1; j < edges.size(); ++j) {
      const Edge& e = edges[i];
      const Edge& f = edges[j];
      if (e.ring == f.ring && e.size > 3 &&
          ((e.index + 1) % e.size == f.index || (f.index + 1) % f.size == e.index)) {
        // neighbours in one ring share one endpoint by construction: they must only not fold back
        if (on_segment(e.a, e.b, f.a == e.b ? f.b : f.a) || on_segment(f.a, f.b, e.a == f.b ? e.b : e.a))
          return "ring folds back at an edge";
        continue;
      }
      if (e.ring == f.ring && e.size == 3) continue;  // a triangle with positive area is simple
      if (segments_clash(e.a, e.b, f.a, f.b)) return "edges clash in rings " + std::to_string(e.ring) + ", " + std::to_string(f.ring);
    }
  for (std::size_t p = 0; p < plans.size(); ++p) {
    const Polygon& poly = plans[p].polygon;
    if (!(signed_area(poly.outer) > 0)) return "outer ring of plan " + std::to_string(p) + " is not CCW";
    for (const auto& h : poly.holes) {
      if (!(signed_area(h) < 0)) return "a hole of plan " + std::to_string(p) + " is not CW";
      for (const auto& v : h)
        if (locate(v, poly.outer) < 0) return "a hole of plan " + std::to_string(p) + " left its shell";
    }
    for (std::size_t q = 0; q < plans.size(); ++q) {
      if (q == p) continue;
      for (const auto& v : plans[q].polygon.outer) {
        if (locate(v, poly.outer) <= 0) continue;
        bool in_hole = false;
        for (const auto& h : poly.holes) in_hole = in_hole || locate(v, h) >= 0;
        if (!in_hole) return "plans " + std::to_string(p) + " and " + std::to_string(q) + " overlap";
      }
    }
  }
  return {};
}

double dist_to_ring(const Point2& p, const Ring& r) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Point2& a = r[i];
    const Point2& b = r[(i + 1) % r.size()];
    const double ux = b.x - a.x, uy = b.y - a.y, l2 = ux * ux + uy * uy;
    const double t = l2 > 0 ? std::clamp(((p.x - a.x) * ux + (p.y - a.y) * uy) / l2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::hypot(p.x - a.x - t * ux, p.y - a.y - t * uy));
  }
  return best;
}

/// Hausdorff distance between two rings, sampled: 16 points per edge each way.
double hausdorff(const Ring& a, const Ring& b) {
  double d = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const Ring& from = pass ? b : a;
    const Ring& to = pass ? a : b;
    for (std::size_t i = 0; i < from.size(); ++i)
      for (int k = 0; k < 16; ++k) {
        const Point2& p = from[i];
        const Point2& q = from[(i + 1) % from.size()];
        const double t = k / 16.0;
        d = std::max(d, dist_to_ring({p.x + t * (q.x - p.x), p.y + t * (q.y - p.y)}, to));
      }
  }
  return d;
}

TEST(LodSimplify, NoisyZigZagWallBecomesStraight) {
  // A 10 x 5 rectangle whose bottom wall zig-zags by +-1 cm through 9 extra vertices.
  Ring outer{{0, 0}};
  for (int i = 1; i <= 9; ++i) outer.push_back({double(i), i % 2 ? 0.01 : -0.01});
  outer.insert(outer.end(), {{10, 0}, {10, 5}, {0, 5}});
  const std::vector<GroundPlan> in{plan(outer)};
  ASSERT_EQ(validity_problem(in), "");
  LodStats stats;
  const auto out = simplify_plans(in, 0.05, &stats);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].polygon.outer, (Ring{{0, 0}, {10, 0}, {10, 5}, {0, 5}}));
  EXPECT_EQ(stats.simplify_vertices_before, 13u);
  EXPECT_EQ(stats.simplify_vertices_after, 4u);
  EXPECT_DOUBLE_EQ(out[0].area_m2, 50.0);
  EXPECT_EQ(out[0].members, in[0].members);
  EXPECT_LE(hausdorff(outer, out[0].polygon.outer), 0.05);
}

TEST(LodSimplify, ToleranceBelowTheNoiseKeepsTheZigZag) {
  Ring outer{{0, 0}};
  for (int i = 1; i <= 9; ++i) outer.push_back({double(i), i % 2 ? 0.01 : -0.01});
  outer.insert(outer.end(), {{10, 0}, {10, 5}, {0, 5}});
  const auto out = simplify_plans({plan(outer)}, 0.005);
  EXPECT_EQ(out[0].polygon.outer, outer);
}

TEST(LodSimplify, HoleNextToAWallDentStaysInside) {
  // The shell's bottom wall dips 4 cm at x = 10 and a hole's tip sits in the dip, 2 cm below the
  // line y = 0. Plain Douglas-Peucker (T = 5 cm) would straighten the wall and leave the tip outside.
  const Ring shell{{0, 0}, {9, 0}, {10, -0.04}, {11, 0}, {20, 0}, {20, 10}, {0, 10}};
  const Ring hole{{10, -0.02}, {9.5, 3}, {10.5, 3}};
  const Ring naive{{0, 0}, {20, 0}, {20, 10}, {0, 10}};
  ASSERT_LT(locate(hole[0], naive), 0);  // the trap is real
  const std::vector<GroundPlan> in{plan(shell, {hole})};
  ASSERT_EQ(validity_problem(in), "");
  const auto out = simplify_plans(in, 0.05);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(validity_problem(out), "");
  // The dip stays; the vertices beside it, 3.6 cm off the new walls, go.
  EXPECT_EQ(out[0].polygon.outer, (Ring{{0, 0}, {10, -0.04}, {20, 0}, {20, 10}, {0, 10}}));
  ASSERT_EQ(out[0].polygon.holes.size(), 1u);
  EXPECT_EQ(out[0].polygon.holes[0], hole);
  EXPECT_NEAR(out[0].area_m2, polygon_area(out[0].polygon), 1e-12);
}

TEST(LodSimplify, SmallHoleInsideAWallDentStaysInside) {
  // A 2 cm hole lies entirely in the dent: no edge would cross the straightened wall, only the
  // vertex test sees that the hole would end up outside.
  const Ring shell{{0, 0}, {9, 0}, {10, -0.04}, {11, 0}, {20, 0}, {20, 10}, {0, 10}};
  const Ring hole{{10, -0.03}, {9.9, -0.01}, {10.1, -0.01}};
  ASSERT_LT(locate(hole[1], Ring{{0, 0}, {20, 0}, {20, 10}, {0, 10}}), 0);  // the trap is real
  const std::vector<GroundPlan> in{plan(shell, {hole})};
  ASSERT_EQ(validity_problem(in), "");
  const auto out = simplify_plans(in, 0.05);
  EXPECT_EQ(validity_problem(out), "");
  EXPECT_EQ(out[0].polygon.outer, (Ring{{0, 0}, {10, -0.04}, {20, 0}, {20, 10}, {0, 10}}));
  ASSERT_EQ(out[0].polygon.holes.size(), 1u);
  EXPECT_EQ(out[0].polygon.holes[0], hole);
}

TEST(LodSimplify, SmallPlanInANeighboursNotchKeepsTheNotch) {
  // C (2 cm) sits in A's 5 cm notch without touching it: straightening A's wall would swallow C.
  const Ring a{{0, 0}, {10, 0}, {10, 4}, {9.95, 5}, {10, 6}, {10, 10}, {0, 10}};
  const Ring c{{9.97, 4.95}, {9.99, 4.95}, {9.98, 5.05}};
  const std::vector<GroundPlan> in{plan(a, {}, {0}), plan(c, {}, {1})};
  ASSERT_EQ(validity_problem(in), "");
  const auto out = simplify_plans(in, 0.1);
  EXPECT_EQ(validity_problem(out), "");
  EXPECT_EQ(out[0].polygon.outer, (Ring{{0, 0}, {10, 0}, {9.95, 5}, {10, 10}, {0, 10}}));
  EXPECT_EQ(out[1].polygon.outer, c);
}

TEST(LodSimplify, PlansOneCentimetreApartDoNotStartToOverlap) {
  // A's right wall has a 5 cm notch at y = 5; B's left wall, 1 cm away, has a spike whose tip sits
  // in the notch. Straightening A's wall (T = 10 cm) would put B's tip inside A. Both walls carry
  // 1 mm noise.
  Ring a{{0, 0}, {10, 0}, {10.001, 2}, {10, 4}, {9.95, 5}, {10, 6}, {9.999, 8}, {10, 10}, {0, 10}};
  Ring b{{10.01, 0}, {20, 0}, {20, 10}, {10.01, 10}, {10.011, 8}, {10.01, 6}, {9.97, 5}, {10.01, 4}, {10.009, 2}};
  const std::vector<GroundPlan> in{plan(a, {}, {0}), plan(b, {}, {1})};
  ASSERT_EQ(validity_problem(in), "");
  ASSERT_GT(locate({9.97, 5}, Ring{{0, 0}, {10, 0}, {10, 10}, {0, 10}}), 0);  // the trap is real
  LodStats stats;
  const auto out = simplify_plans(in, 0.1, &stats);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(validity_problem(out), "");
  // A is simplified first and keeps the notch's tip (B's tip is in the notch), straight to it
  // from (10, 0) and from it to (10, 10). B then loses its spike: A's vertices are all outside it.
  EXPECT_EQ(out[0].polygon.outer, (Ring{{0, 0}, {10, 0}, {9.95, 5}, {10, 10}, {0, 10}}));
  EXPECT_EQ(out[1].polygon.outer, (Ring{{10.01, 0}, {20, 0}, {20, 10}, {10.01, 10}}));
  EXPECT_EQ(out[1].members, (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(stats.simplify_vertices_before, 18u);
  EXPECT_EQ(stats.simplify_vertices_after, 9u);
  EXPECT_LE(hausdorff(a, out[0].polygon.outer), 0.1);
  EXPECT_LE(hausdorff(b, out[1].polygon.outer), 0.1);
}

TEST(LodSimplify, PlansTouchingAtAPointKeepThePoint) {
  // (10, 10) is 2 cm above A's nearly flat top and is where B touches A: it stays.
  const Ring a{{0, 0}, {20, 0}, {20, 9.98}, {10, 10}, {0, 9.98}};
  const Ring b{{10, 10}, {12, 12}, {8, 12}};
  const std::vector<GroundPlan> in{plan(a), plan(b)};
  const auto out = simplify_plans(in, 0.05);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].polygon.outer, a);
  EXPECT_EQ(out[1].polygon.outer, b);
  EXPECT_EQ(validity_problem(out), "");
  // Without B, the point goes.
  const auto alone = simplify_plans({plan(a)}, 0.05);
  EXPECT_EQ(alone[0].polygon.outer.size(), 4u);
}

TEST(LodSimplify, HoleTouchingItsShellKeepsTheTouchPoint) {
  // The hole's top vertex touches the shell's top wall at (5, 10), nearly collinear with its
  // neighbours (0, 10.01) and (10, 10.01).
  const Ring shell{{0, 0}, {10, 0}, {10, 10.01}, {5, 10}, {0, 10.01}};
  const Ring hole{{5, 10}, {6, 5}, {4, 5}};
  const std::vector<GroundPlan> in{plan(shell, {hole})};
  ASSERT_EQ(validity_problem(in), "");
  const auto out = simplify_plans(in, 0.05);
  EXPECT_EQ(out[0].polygon.outer, shell);
  EXPECT_EQ(validity_problem(out), "");
}

TEST(LodSimplify, ARingKeepsAtLeastThreeVerticesAndItsOrientation) {
  // A thin sliver 4 cm high: T = 1 m could flatten it to a line; it stays a triangle, CW as a hole
  // and CCW as a shell.
  const Ring sliver{{0, 0}, {5, 0.01}, {10, 0}, {5, 0.04}};
  const auto out = simplify_plans({plan(sliver)}, 1.0);
  ASSERT_EQ(out[0].polygon.outer.size(), 3u);
  EXPECT_GT(signed_area(out[0].polygon.outer), 0);
  EXPECT_EQ(validity_problem(out), "");
  const Ring shell{{-1, -1}, {11, -1}, {11, 1}, {-1, 1}};
  Ring hole(sliver.rbegin(), sliver.rend());
  const auto out2 = simplify_plans({plan(shell, {hole})}, 1.0);
  ASSERT_EQ(out2[0].polygon.holes.size(), 1u);
  EXPECT_EQ(out2[0].polygon.holes[0].size(), 3u);
  EXPECT_LT(signed_area(out2[0].polygon.holes[0]), 0);
  EXPECT_EQ(validity_problem(out2), "");
}

TEST(LodSimplify, AShortcutDownLeftOfTheFirstVertexSeesTheEdgeItWouldCross) {
  // fuzz_lod's b16fa889 (tests/corpus/fuzz-regressions/lod/): the plan that --snap 0.3 and
  // --close-gaps 2.5 made of it, simplified with T = 2.5. The edge index's cells are counted from the
  // first vertex (the top right here); the shortcut (0, 11/7) -> (96/7, 0) lies in the cell down-left
  // of it, cell (-1, -1), which the index packed to its empty-slot key, so the edge (4.79, 0.55) ->
  // (255/7, 50/7) there was never found and the shortcut crossed it: a self-intersecting plan.
  const Ring ring{{35, 35.142857142857146},
                  {0.8571428571428571, 1.4285714285714286},
                  {0, 1.5714285714285714},
                  {0.42857142857142855, 0.7142857142857143},
                  {0.8571428571428571, 0},
                  {13.714285714285714, 0},
                  {4.7877551020408164, 0.55102040816326525},
                  {36.428571428571431, 7.1428571428571432}};
  const std::vector<GroundPlan> in{plan(ring)};
  ASSERT_EQ(validity_problem(in), "");
  const auto out = simplify_plans(in, 2.5);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(validity_problem(out), "");
  EXPECT_LE(hausdorff(ring, out[0].polygon.outer), 2.5 + 1e-9);
  EXPECT_LT(out[0].polygon.outer.size(), ring.size());  // it does simplify: (0.86, 1.43) goes
}

TEST(LodSimplify, RejectsANonPositiveOrNonFiniteTolerance) {
  const std::vector<GroundPlan> in{plan({{0, 0}, {1, 0}, {1, 1}, {0, 1}})};
  EXPECT_THROW(simplify_plans(in, 0), InvalidArgument);
  EXPECT_THROW(simplify_plans(in, -0.1), InvalidArgument);
  EXPECT_THROW(simplify_plans(in, std::numeric_limits<double>::quiet_NaN()), InvalidArgument);
  EXPECT_THROW(simplify_plans(in, std::numeric_limits<double>::infinity()), InvalidArgument);
}

}  // namespace
}  // namespace groundplan

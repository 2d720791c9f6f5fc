// SPDX-License-Identifier: MIT
// --snap (issue 9): almost-touching walls become shared, nothing moves more than the tolerance.
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "union_generators.h"
#include "union_test_util.h"

namespace groundplan {
namespace {

using testing::footprints_from_wkt;

std::vector<GroundPlan> plans_of(const std::vector<Footprint>& fps) {
  std::vector<Problem> problems;
  UnionParams params;
  params.threads = 1;
  return build_ground_plans(fps, params, problems);
}

double total_area(const std::vector<GroundPlan>& plans) {
  double a = 0;
  for (const auto& p : plans) a += p.area_m2;
  return a;
}

std::size_t holes(const std::vector<GroundPlan>& plans) {
  std::size_t n = 0;
  for (const auto& p : plans) n += p.polygon.holes.size();
  return n;
}

double seg_dist(const Point2& p, const Point2& a, const Point2& b) {
  const double ux = b.x - a.x, uy = b.y - a.y, l2 = ux * ux + uy * uy;
  const double t = l2 > 0 ? std::clamp(((p.x - a.x) * ux + (p.y - a.y) * uy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - a.x - t * ux, p.y - a.y - t * uy);
}

/// The outer ring of footprint f's first polygon; empty when it has none (so a failing test
/// reports instead of crashing).
Ring outer(const std::vector<Footprint>& fps, std::size_t f) {
  return f < fps.size() && !fps[f].polygons.empty() ? fps[f].polygons[0].outer : Ring{};
}

/// The ring started at its smallest point (x, then y): the union may start a ring elsewhere when the
/// input has extra collinear vertices, which is the same ring.
Ring canonical(Ring r) {
  auto less = [](const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); };
  std::rotate(r.begin(), std::min_element(r.begin(), r.end(), less), r.end());
  return r;
}

/// Whether every vertex of `in` has a vertex of `out` within d, in the same cyclic order (each
/// input vertex goes to one output vertex, consecutive input vertices to the same or later ones:
/// the output ring is the input ring with each vertex moved by at most d, plus insertions).
bool follows_within(const Ring& in, const Ring& out, double d) {
  const std::size_t m = out.size();
  auto near = [&](const Point2& p, std::size_t j) { return std::hypot(p.x - out[j % m].x, p.y - out[j % m].y) <= d; };
  for (std::size_t j0 = 0; j0 < m; ++j0) {
    if (!near(in[0], j0)) continue;
    std::size_t j = j0;
    bool ok = true;
    // Greedy earliest match: if any monotone matching exists from j0, this finds one.
    for (std::size_t i = 1; i < in.size() && ok; ++i) {
      while (j < j0 + m && !near(in[i], j)) ++j;
      ok = j < j0 + m;
    }
    if (ok) return true;
  }
  return false;
}

TEST(LodSnap, TwoSquaresHalfAMillimetreApartBecomeOnePlan) {
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))",
                                        "POLYGON((10.0005 0, 20 0, 20 10, 10.0005 10, 10.0005 0))"});
  ASSERT_EQ(plans_of(fps).size(), 2u);  // the gap is real without --snap
  LodStats stats;
  const auto snapped = snap_footprints(fps, 0.001, &stats);
  ASSERT_EQ(snapped.size(), 2u);
  const auto plans = plans_of(snapped);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(holes(plans), 0u);
  EXPECT_NEAR(total_area(plans), 200.0, 0.0051);  // the 0.5 mm x 10 m gap closes: +0.005 m²
  EXPECT_EQ(stats.snap_vertices_moved, 2u);       // the second square's left corners
  EXPECT_EQ(stats.snap_vertices_inserted, 0u);
  EXPECT_EQ(stats.snap_rings_collapsed, 0u);
  EXPECT_EQ(plans[0].members, (std::vector<std::uint32_t>{0, 1}));
}

TEST(LodSnap, SliverHoleBetweenNearParallelWallsDisappears) {
  // A and B are closed above and below by C and D; B's left wall leans away from A's right wall by
  // 1e-7 m at the bottom and 5e-4 m at the top: a sliver hole in the exact union.
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))",
                                        "POLYGON((10.0000001 0, 20 0, 20 10, 10.0005 10, 10.0000001 0))",
                                        "POLYGON((0 10, 20 10, 20 12, 0 12, 0 10))",
                                        "POLYGON((0 -2, 20 -2, 20 0, 0 0, 0 -2))"});
  const auto exact = plans_of(fps);
  ASSERT_EQ(exact.size(), 1u);
  ASSERT_EQ(holes(exact), 1u);
  const auto plans = plans_of(snap_footprints(fps, 0.001));
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(holes(plans), 0u);
  EXPECT_NEAR(total_area(plans), 280.0, 1e-9);
}

TEST(LodSnap, TJunctionJoinsTheWallThatEndsInTheMiddleOfANeighboursWall) {
  // B's left wall (y 2..8) stands 0.3 mm off the middle of A's right wall (y 0..10): no vertex of
  // either is near a vertex of the other, only near an edge.
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))",
                                        "POLYGON((10.0003 2, 15 2, 15 8, 10.0003 8, 10.0003 2))"});
  ASSERT_EQ(plans_of(fps).size(), 2u);
  LodStats stats;
  const auto snapped = snap_footprints(fps, 0.001, &stats);
  EXPECT_EQ(stats.snap_vertices_moved, 0u);
  EXPECT_EQ(stats.snap_vertices_inserted, 2u);
  // B's corners themselves go into A's wall, in order along it.
  const Ring expected_a{{0, 0}, {10, 0}, {10.0003, 2}, {10.0003, 8}, {10, 10}, {0, 10}};
  ASSERT_EQ(snapped[0].polygons.size(), 1u);
  EXPECT_EQ(outer(snapped, 0), expected_a);
  EXPECT_EQ(outer(snapped, 1), fps[1].polygons[0].outer);
  const auto plans = plans_of(snapped);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(holes(plans), 0u);
  EXPECT_NEAR(total_area(plans), 100.0 + 4.9997 * 6 + 0.0003 * 6 + 0.0003 * 2 * 0.5 * 2, 1e-9);
}

TEST(LodSnap, VerticesFartherApartThanTheToleranceStay) {
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))",
                                        "POLYGON((10.0011 0, 20 0, 20 10, 10.0011 10, 10.0011 0))"});
  LodStats stats;
  const auto snapped = snap_footprints(fps, 0.001, &stats);
  ASSERT_EQ(snapped.size(), 2u);
  for (std::size_t f = 0; f < 2; ++f) EXPECT_EQ(outer(snapped, f), fps[f].polygons[0].outer);
  EXPECT_EQ(stats.snap_vertices_moved, 0u);
  EXPECT_EQ(stats.snap_vertices_inserted, 0u);
  EXPECT_EQ(plans_of(snapped).size(), 2u);
}

TEST(LodSnap, NoChainingAlongALineOfClosePoints) {
  // Points 0.9 apart with tolerance 1: 0.9 moves onto 0, 1.8 is 1.8 from 0 and is kept, 2.7 moves
  // onto 1.8. Chaining would have pulled them all onto 0.
  Footprint f;
  f.source_id = "line";
  f.source_file = "f.gml";
  f.method = "ground-surface";
  f.min_z = 1;
  f.max_z = 7;
  f.polygons.push_back({{{0, 0}, {0.9, 0}, {1.8, 0}, {2.7, 0}, {2.7, 5}, {0, 5}}, {}});
  LodStats stats;
  const auto snapped = snap_footprints({f}, 1.0, &stats);
  ASSERT_EQ(snapped.size(), 1u);
  ASSERT_EQ(snapped[0].polygons.size(), 1u);
  EXPECT_EQ(outer(snapped, 0), (Ring{{0, 0}, {1.8, 0}, {2.7, 5}, {0, 5}}));
  EXPECT_EQ(stats.snap_vertices_moved, 2u);
  EXPECT_EQ(snapped[0].source_id, "line");
  EXPECT_EQ(snapped[0].source_file, "f.gml");
  EXPECT_EQ(snapped[0].method, "ground-surface");
  EXPECT_EQ(snapped[0].min_z, 1);
  EXPECT_EQ(snapped[0].max_z, 7);
}

TEST(LodSnap, MovesToTheNearestKeptVertex) {
  // (1.7, 0.1) is within 1 of both kept vertices (0.8, 0) and (2.4, 0); the latter is nearer.
  Footprint f;
  f.polygons.push_back({{{0.8, 0}, {2.4, 0}, {1.7, 0.1}, {1.6, 9}}, {}});
  const auto snapped = snap_footprints({f}, 1.0);
  EXPECT_EQ(outer(snapped, 0), (Ring{{0.8, 0}, {2.4, 0}, {1.6, 9}}));
}

TEST(LodSnap, CollapsedRingsAreDroppedAndCounted) {
  // A 0.5 mm triangle and a 0.5 mm hole vanish; the footprint stays (members index the input).
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (5 5, 5 5.0005, 5.0005 5, 5 5))",
                                        "POLYGON((30 0, 30.0005 0, 30 0.0004, 30 0))"});
  LodStats stats;
  const auto snapped = snap_footprints(fps, 0.001, &stats);
  ASSERT_EQ(snapped.size(), 2u);
  ASSERT_EQ(snapped[0].polygons.size(), 1u);
  ASSERT_EQ(snapped[0].polygons.size(), 1u);
  EXPECT_TRUE(snapped[0].polygons[0].holes.empty());
  EXPECT_TRUE(snapped[1].polygons.empty());
  EXPECT_EQ(stats.snap_rings_collapsed, 2u);
}

TEST(LodSnap, NonFinitePointsStayAndTakePartInNothing) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Footprint f;
  f.polygons.push_back({{{0, 0}, {10, 0}, {nan, 5}, {10, 10}, {0, 10}}, {}});
  Footprint g;
  g.polygons.push_back({{{10.0004, 0}, {20, 0}, {20, 10}}, {}});
  LodStats stats;
  const auto snapped = snap_footprints({f, g}, 0.001, &stats);
  ASSERT_EQ(outer(snapped, 0).size(), 5u);
  EXPECT_TRUE(std::isnan(outer(snapped, 0)[2].x));
  EXPECT_EQ(outer(snapped, 1), (Ring{{10, 0}, {20, 0}, {20, 10}}));
  EXPECT_EQ(stats.snap_vertices_moved, 1u);
}

TEST(LodSnap, RejectsANonPositiveOrNonFiniteTolerance) {
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))"});
  EXPECT_THROW(snap_footprints(fps, 0), InvalidArgument);
  EXPECT_THROW(snap_footprints(fps, -1), InvalidArgument);
  EXPECT_THROW(snap_footprints(fps, std::numeric_limits<double>::infinity()), InvalidArgument);
  EXPECT_THROW(snap_footprints(fps, std::numeric_limits<double>::quiet_NaN()), InvalidArgument);
}

// On a synthetic city whose vertices are shaken by up to 0.2 m in x and y (so that neighbours' shared
// corners end up anywhere from 0 to 0.57 m apart), with tolerance 0.3 m: every output vertex is an
// input vertex, and every input vertex has an output vertex of its ring within tol (a vertex moves
// at most tol). An inserted vertex is within tol of the snapped edge, whose ends moved by up to tol:
// so within 2 tol of the input ring.
TEST(LodSnap, NothingMovesMoreThanTheToleranceOnACity) {
  auto city = testing::synthetic_city(1500, 5);
  testing::Rng rng(17);
  std::uniform_real_distribution<double> shake(-0.2, 0.2);
  for (auto& f : city)
    for (auto& p : f.polygons) {
      for (auto& q : p.outer) q = {q.x + shake(rng), q.y + shake(rng)};
      for (auto& h : p.holes)
        for (auto& q : h) q = {q.x + shake(rng), q.y + shake(rng)};
    }
  const double tol = 0.3;
  LodStats stats;
  const auto snapped = snap_footprints(city, tol, &stats);
  ASSERT_EQ(snapped.size(), city.size());
  EXPECT_GT(stats.snap_vertices_moved, 100u);
  EXPECT_GT(stats.snap_vertices_inserted, 100u);
  std::vector<std::pair<double, double>> input_points;
  for (const auto& f : city)
    for (const auto& p : f.polygons) {
      for (const auto& q : p.outer) input_points.emplace_back(q.x, q.y);
      for (const auto& h : p.holes)
        for (const auto& q : h) input_points.emplace_back(q.x, q.y);
    }
  std::sort(input_points.begin(), input_points.end());
  std::size_t rings_compared = 0;
  const double slack = 1e-9;
  auto check_ring = [&](const Ring& in, const Ring& out) {
    ++rings_compared;
    for (const auto& q : out) {
      EXPECT_TRUE(std::binary_search(input_points.begin(), input_points.end(), std::make_pair(q.x, q.y)));
      double d = 1e300;
      for (std::size_t i = 0; i < in.size(); ++i) d = std::min(d, seg_dist(q, in[i], in[(i + 1) % in.size()]));
      EXPECT_LE(d, 2 * tol + slack);
    }
    EXPECT_TRUE(follows_within(in, out, tol + slack));
  };
  for (std::size_t f = 0; f < city.size(); ++f) {
    const auto& a = city[f].polygons;
    const auto& b = snapped[f].polygons;
    if (a.size() != b.size()) continue;  // a polygon collapsed: rings no longer correspond
    for (std::size_t k = 0; k < a.size(); ++k) {
      check_ring(a[k].outer, b[k].outer);
      if (a[k].holes.size() == b[k].holes.size())
        for (std::size_t h = 0; h < a[k].holes.size(); ++h) check_ring(a[k].holes[h], b[k].holes[h]);
    }
  }
  EXPECT_GT(rings_compared, 1400u);
  // The snapped city still unites into valid plans.
  const auto plans = plans_of(snapped);
  EXPECT_GT(plans.size(), 10u);
}

TEST(LodSnap, TinyToleranceLeavesTheUnionUnchanged) {
  const auto city = testing::synthetic_city(2000, 9);
  LodStats stats;
  const auto snapped = snap_footprints(city, 1e-12, &stats);
  EXPECT_EQ(stats.snap_vertices_moved, 0u);
  const auto a = plans_of(city), b = plans_of(snapped);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(canonical(a[i].polygon.outer) == canonical(b[i].polygon.outer)) << "plan " << i;
    ASSERT_EQ(a[i].polygon.holes.size(), b[i].polygon.holes.size()) << "plan " << i;
    for (std::size_t h = 0; h < a[i].polygon.holes.size(); ++h)
      EXPECT_TRUE(canonical(a[i].polygon.holes[h]) == canonical(b[i].polygon.holes[h])) << "plan " << i;
    EXPECT_EQ(a[i].members, b[i].members) << "plan " << i;
  }
}

}  // namespace
}  // namespace groundplan

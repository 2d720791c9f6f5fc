// SPDX-License-Identifier: MIT
// The union engine on each degenerate family, WKT in, GEOS UnaryUnion as the reference (issue 3).
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include "union_generators.h"
#include "union_test_util.h"

namespace groundplan {
namespace {

using testing::footprints_from_wkt;
using testing::run_and_compare;

void expect_union(const std::vector<std::string>& wkts, std::size_t plans, std::size_t holes) {
  const auto fps = footprints_from_wkt(wkts);
  const auto c = run_and_compare(fps);
  EXPECT_TRUE(c.ok) << c.message;
  EXPECT_EQ(c.cmp.polygons_ours, plans) << c.message;
  EXPECT_EQ(c.cmp.holes_ours, holes) << c.message;
}

TEST(UnionEngine, SingleSquare) { expect_union({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))"}, 1, 0); }

TEST(UnionEngine, ClockwiseInputComesOutCounterClockwise) {
  expect_union({"POLYGON((0 0, 0 10, 10 10, 10 0, 0 0))"}, 1, 0);
}

TEST(UnionEngine, TwoOverlappingSquares) {
  expect_union({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))", "POLYGON((5 5, 15 5, 15 15, 5 15, 5 5))"}, 1, 0);
}

TEST(UnionEngine, DisjointSquaresAreTwoPlans) {
  expect_union({"POLYGON((0 0, 1 0, 1 1, 0 1, 0 0))", "POLYGON((3 0, 4 0, 4 1, 3 1, 3 0))"}, 2, 0);
}

TEST(UnionEngine, PartyWallRowHouses) {
  expect_union({"POLYGON((0 0, 6 0, 6 10, 0 10, 0 0))", "POLYGON((6 0, 12 0, 12 10, 6 10, 6 0))",
                "POLYGON((12 0, 18 0, 18 10, 12 10, 12 0))"},
               1, 0);
}

TEST(UnionEngine, PartialPartyWallCollinearOverlap) {
  expect_union({"POLYGON((0 0, 6 0, 6 10, 0 10, 0 0))", "POLYGON((6 3, 12 3, 12 14, 6 14, 6 3))"}, 1, 0);
}

TEST(UnionEngine, CollinearOverlappingEdgesSameDirection) {
  expect_union({"POLYGON((0 0, 10 0, 10 5, 0 5, 0 0))", "POLYGON((3 0, 13 0, 13 4, 3 4, 3 0))"}, 1, 0);
}

TEST(UnionEngine, TouchingAtOneVertexAreTwoPlans) {
  expect_union({"POLYGON((0 0, 1 0, 1 1, 0 1, 0 0))", "POLYGON((1 1, 2 1, 2 2, 1 2, 1 1))"}, 2, 0);
}

TEST(UnionEngine, VertexTouchingEdgeInterior) {
  // the triangle's tip touches the square's edge at one point: two plans, as GEOS
  expect_union({"POLYGON((0 0, 4 0, 4 4, 0 4, 0 0))", "POLYGON((4 2, 6 0, 6 4, 4 2))"}, 2, 0);
  // a tip pushed one unit in: one plan
  expect_union({"POLYGON((0 0, 4 0, 4 4, 0 4, 0 0))", "POLYGON((3 2, 6 0, 6 4, 3 2))"}, 1, 0);
}

TEST(UnionEngine, NestedPolygonInsideAnother) {
  expect_union({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))", "POLYGON((2 2, 4 2, 4 4, 2 4, 2 2))"}, 1, 0);
}

TEST(UnionEngine, IdenticalDuplicates) {
  expect_union({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))", "POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))",
                "POLYGON((10 10, 0 10, 0 0, 10 0, 10 10))"},
               1, 0);
}

TEST(UnionEngine, BowTieIsTwoTrianglesTouching) {
  expect_union({"POLYGON((0 0, 10 10, 10 0, 0 10, 0 0))"}, 2, 0);
}

TEST(UnionEngine, RepeatedPoints) {
  expect_union({"POLYGON((0 0, 0 0, 10 0, 10 0, 10 0, 10 10, 0 10, 0 10, 0 0))"}, 1, 0);
}

TEST(UnionEngine, ZeroAreaSliverIsAProblemNotAPlan) {
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 5 0, 0 0))", "POLYGON((20 0, 30 0, 30 10, 20 0))"});
  std::vector<Problem> problems;
  const auto plans = build_ground_plans(fps, UnionParams{}, problems);
  ASSERT_EQ(plans.size(), 1u);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].code, "NO_AREA");
  EXPECT_EQ(problems[0].source_id, "f0");
  EXPECT_EQ(plans[0].members, std::vector<std::uint32_t>{1});
}

TEST(UnionEngine, SelfRetracingRingIsAProblemNotLostSilently) {
  // A-B-C-B-A: every edge twice, no area under the even-odd rule (fuzz finding, issue 8)
  std::vector<Footprint> fps(2);
  fps[0].source_id = "retrace";
  fps[0].polygons.push_back(Polygon{{{0, 3}, {10, 0}, {10, 3}, {10, 0}}, {}});
  fps[1].source_id = "square";
  fps[1].polygons.push_back(Polygon{{{20, 0}, {30, 0}, {30, 10}, {20, 10}}, {}});
  std::vector<Problem> problems;
  const auto plans = build_ground_plans(fps, UnionParams{}, problems);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].members, std::vector<std::uint32_t>{1});
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].source_id, "retrace");
  EXPECT_EQ(problems[0].code, "NO_AREA");
  EXPECT_EQ(problems[0].stage, "union");
}

TEST(UnionEngine, InscribedFootprintIsAMember) {
  // the triangle's vertices all lie on the square's boundary: located by its edges' midpoints
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))", "POLYGON((0 0, 10 5, 0 10, 0 0))"});
  std::vector<Problem> problems;
  const auto plans = build_ground_plans(fps, UnionParams{}, problems);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].members, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_TRUE(problems.empty());
}

TEST(UnionEngine, SliverSpikeOnASquare) {
  expect_union({"POLYGON((0 0, 10 0, 10 5, 15 5, 10 5, 10 10, 0 10, 0 0))"}, 1, 0);
}

TEST(UnionEngine, CourtyardHole) {
  expect_union({"POLYGON((0 0, 20 0, 20 20, 0 20, 0 0), (5 5, 5 15, 15 15, 15 5, 5 5))"}, 1, 1);
}

TEST(UnionEngine, RingOfBuildingsMakesAHole) {
  expect_union({"POLYGON((0 0, 20 0, 20 5, 0 5, 0 0))", "POLYGON((15 0, 20 0, 20 20, 15 20, 15 0))",
                "POLYGON((0 15, 20 15, 20 20, 0 20, 0 15))", "POLYGON((0 0, 5 0, 5 20, 0 20, 0 0))"},
               1, 1);
}

TEST(UnionEngine, HoleFilledByAnotherFootprint) {
  expect_union({"POLYGON((0 0, 20 0, 20 20, 0 20, 0 0), (5 5, 5 15, 15 15, 15 5, 5 5))",
                "POLYGON((5 5, 15 5, 15 15, 5 15, 5 5))"},
               1, 0);
}

TEST(UnionEngine, IslandInsideCourtyard) {
  expect_union({"POLYGON((0 0, 20 0, 20 20, 0 20, 0 0), (5 5, 5 15, 15 15, 15 5, 5 5))",
                "POLYGON((8 8, 12 8, 12 12, 8 12, 8 8))"},
               2, 1);
}

TEST(UnionEngine, HoleTouchingShellAtOnePoint) {
  expect_union({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (0 5, 5 2, 5 8, 0 5))"}, 1, 1);
  // two L-shaped footprints enclosing a triangle that touches the outside at one vertex
  expect_union({"POLYGON((0 0, 10 0, 10 5, 5 5, 0 2, 0 0))", "POLYGON((0 2, 5 5, 10 5, 10 10, 0 10, 0 2))",
                "POLYGON((5 5, 10 5, 10 6, 5 5))"},
               1, 0);
}

TEST(UnionEngine, SubMillimetreHoleFarBelowPixelSize) {
  // four big footprints leave a 2e-4 x 1e-4 m gap between them: a hole no raster would see
  expect_union({"POLYGON((0 0, 100 0, 100 50, 0 50, 0 0))", "POLYGON((0 50.0001, 100 50.0001, 100 100, 0 100, 0 50.0001))",
                "POLYGON((0 49, 50 49, 50 51, 0 51, 0 49))", "POLYGON((50.0002 49, 100 49, 100 51, 50.0002 51, 50.0002 49))"},
               1, 1);
}

TEST(UnionEngine, TinySeparateIslandNextToBigBuilding) {
  expect_union({"POLYGON((0 0, 100 0, 100 100, 0 100, 0 0))", "POLYGON((100.001 50, 100.002 50, 100.002 50.001, 100.001 50))"},
               2, 0);
}

TEST(UnionEngine, LargeCoordinatesWithMillimetreFeatures) {
  expect_union({"POLYGON((5000000 3000000, 5000010 3000000, 5000010 3000010, 5000000 3000010, 5000000 3000000))",
                "POLYGON((5000010 3000000, 5000020 3000000.001, 5000020 3000010, 5000010 3000010, 5000010 3000000))",
                "POLYGON((5000009.999 3000005, 5000010.002 3000005, 5000010.002 3000005.003, 5000009.999 3000005))"},
               1, 0);
}

TEST(UnionEngine, CrossingWingsNoVertexAtCrossings) {
  expect_union({"POLYGON((0 4, 20 4, 20 6, 0 6, 0 4))", "POLYGON((9 0, 11 0, 11 20, 9 20, 9 0))",
                "POLYGON((1 1, 19 17, 18 18, 0 2, 1 1))"},
               1, 1);
}

TEST(UnionEngine, StarPolygonEvenOddLikeMakeValid) {
  // GEOS MakeValid: the pentagon in the middle has parity 2, so five triangles touching at points
  expect_union({"POLYGON((0 0, 4 10, 8 0, -2 6, 10 6, 0 0))"}, 5, 0);
}

TEST(UnionEngine, MembersListContributingFootprints) {
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))", "POLYGON((20 0, 30 0, 30 10, 20 10, 20 0))",
                                        "POLYGON((2 2, 3 2, 3 3, 2 3, 2 2))", "POLYGON((10 0, 20 0, 20 1, 10 1, 10 0))"});
  std::vector<Problem> problems;
  const auto plans = build_ground_plans(fps, UnionParams{}, problems);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].members, (std::vector<std::uint32_t>{0, 1, 2, 3}));
  EXPECT_NEAR(plans[0].area_m2, 210.0, 1e-9);
}

TEST(UnionEngine, ParallelOverBlocksIsDeterministicAndMatchesGeos) {
  const auto city = testing::synthetic_city(2000, 7);
  UnionParams one, two;
  one.threads = 1;
  two.threads = 2;
  std::vector<Problem> p1, p2;
  const auto a = build_ground_plans(city, one, p1);
  const auto b = build_ground_plans(city, two, p2);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].polygon.outer, b[i].polygon.outer) << i;
    EXPECT_EQ(a[i].members, b[i].members) << i;
  }
  EXPECT_TRUE(p1.empty());
  const auto c = gis::compare_with_geos(city, b);
  EXPECT_TRUE(c.matches(1e-9)) << c.summary();
}

TEST(UnionEngine, CudaDeviceThrowsWithoutCuda) {
  UnionParams p;
  p.device = Device::Cuda;
  std::vector<Problem> problems;
  EXPECT_THROW(build_ground_plans({}, p, problems), GpuError);
}

TEST(UnionEngine, NegativeResolutionIsInvalid) {
  UnionParams p;
  p.resolution_m = -1;
  std::vector<Problem> problems;
  EXPECT_THROW(build_ground_plans({}, p, problems), InvalidArgument);
}

TEST(UnionEngine, ResolutionDoesNotChangeTheResult) {
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))", "POLYGON((10.001 0, 20 0, 20 10, 10.001 10, 10.001 0))"});
  for (double res : {0.0, 0.0001, 1.0, 100.0}) {
    UnionParams p;
    p.resolution_m = res;
    std::vector<Problem> problems;
    EXPECT_EQ(build_ground_plans(fps, p, problems).size(), 2u) << res;
  }
}

TEST(UnionEngine, CancelledByProgress) {
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))"});
  std::vector<Problem> problems;
  Progress stop([](double, const char*) { return false; });
  EXPECT_THROW(build_ground_plans(fps, UnionParams{}, problems, stop), Cancelled);
}

}  // namespace
}  // namespace groundplan

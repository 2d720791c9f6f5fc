// SPDX-License-Identifier: MIT
// Level of detail (issue 9): the order of the steps, --min-hole-area, --min-area and the paper's raster
// mode (--resolution-mode raster), on cases whose answers are known by construction.
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>

#include <algorithm>
#include <string>

#include "union_test_util.h"

namespace groundplan {
namespace {

using testing::footprints_from_wkt;

constexpr const char* kCourtyard =  // 20 x 20 block with a 10 x 10 yard: area 300
    "POLYGON((0 0, 20 0, 20 20, 0 20, 0 0), (5 5, 5 15, 15 15, 15 5, 5 5))";
constexpr const char* kSmallHoleBlock =  // 10 x 10 block at x=100 with a 0.5 x 0.5 hole: area 99.75
    "POLYGON((100 0, 110 0, 110 10, 100 10, 100 0), (104 4, 104 4.5, 104.5 4.5, 104.5 4, 104 4))";
constexpr const char* kKiosk = "POLYGON((200 0, 201 0, 201 0.5, 200 0.5, 200 0))";  // 0.5 m2

std::vector<Footprint> three() {
  auto fps = footprints_from_wkt({kCourtyard, kSmallHoleBlock, kKiosk});
  fps[0].source_id = "yard";
  fps[1].source_id = "smallhole";
  fps[2].source_id = "kiosk";
  return fps;
}

std::size_t holes(const std::vector<GroundPlan>& plans) {
  std::size_t n = 0;
  for (const auto& g : plans) n += g.polygon.holes.size();
  return n;
}

double total_area(const std::vector<GroundPlan>& plans) {
  double a = 0;
  for (const auto& g : plans) a += g.area_m2;
  return a;
}

std::size_t count_code(const std::vector<Problem>& ps, const std::string& code) {
  return static_cast<std::size_t>(std::count_if(ps.begin(), ps.end(), [&](const Problem& p) { return p.code == code; }));
}

TEST(LodFilters, DefaultParamsAreTheExactUnion) {
  const auto fps = three();
  std::vector<Problem> p1, p2;
  const auto exact = build_ground_plans(fps, UnionParams{}, p1);
  LodStats st;
  const auto same = build_ground_plans(fps, UnionParams{}, LodParams{}, p2, {}, &st);
  ASSERT_EQ(exact.size(), same.size());
  for (std::size_t i = 0; i < exact.size(); ++i) {
    EXPECT_EQ(exact[i].polygon.outer, same[i].polygon.outer);
    EXPECT_EQ(exact[i].polygon.holes, same[i].polygon.holes);
    EXPECT_EQ(exact[i].members, same[i].members);
  }
  EXPECT_EQ(holes(same), 2u);
  EXPECT_NEAR(total_area(same), 300 + 99.75 + 0.5, 1e-9);
}

TEST(LodFilters, MinHoleAreaFillsOnlySmallerHolesAndSaysWhich) {
  const auto fps = three();
  std::vector<Problem> problems;
  LodParams lod;
  lod.min_hole_area_m2 = 1.0;  // the 0.25 m2 hole goes, the 100 m2 yard stays
  LodStats st;
  const auto plans = build_ground_plans(fps, UnionParams{}, lod, problems, {}, &st);
  ASSERT_EQ(plans.size(), 3u);
  EXPECT_EQ(holes(plans), 1u);
  EXPECT_EQ(st.holes_filled, 1u);
  EXPECT_NEAR(st.holes_filled_area_m2, 0.25, 1e-9);
  EXPECT_NEAR(total_area(plans), 300 + 100 + 0.5, 1e-9);
  ASSERT_EQ(count_code(problems, "HOLE_BELOW_MIN_AREA"), 1u);
  const auto it = std::find_if(problems.begin(), problems.end(),
                               [](const Problem& p) { return p.code == "HOLE_BELOW_MIN_AREA"; });
  EXPECT_EQ(it->source_id, "smallhole");
  EXPECT_EQ(it->stage, "lod");
  EXPECT_NE(it->reason.find("0.25 m2"), std::string::npos) << it->reason;
}

TEST(LodFilters, MinAreaDropsPlansAndNamesEveryBuilding) {
  auto fps = three();
  // a second kiosk touching the first: one plan of two buildings, 1.0 m2 together
  fps.push_back(footprints_from_wkt({"POLYGON((201 0, 202 0, 202 0.5, 201 0.5, 201 0))"})[0]);
  fps.back().source_id = "kiosk2";
  std::vector<Problem> problems;
  LodParams lod;
  lod.min_area_m2 = 1.5;
  LodStats st;
  const auto plans = build_ground_plans(fps, UnionParams{}, lod, problems, {}, &st);
  EXPECT_EQ(plans.size(), 2u);
  EXPECT_EQ(st.plans_dropped, 1u);
  EXPECT_NEAR(st.plans_dropped_area_m2, 1.0, 1e-9);
  ASSERT_EQ(count_code(problems, "PLAN_BELOW_MIN_AREA"), 2u);
  std::vector<std::string> named;
  for (const auto& p : problems)
    if (p.code == "PLAN_BELOW_MIN_AREA") named.push_back(p.source_id);
  std::sort(named.begin(), named.end());
  EXPECT_EQ(named, (std::vector<std::string>{"kiosk", "kiosk2"}));
}

TEST(LodFilters, FillingAHoleJoinsTheIslandInsideIt) {
  // a 1 m2 island in a 4 m2 hole: filling the hole must not leave the island overlapping the owner
  auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (4 4, 4 6, 6 6, 6 4, 4 4))",
                                  "POLYGON((4.5 4.5, 5.5 4.5, 5.5 5.5, 4.5 5.5, 4.5 4.5))"});
  std::vector<Problem> problems;
  LodParams lod;
  lod.min_hole_area_m2 = 5;
  const auto plans = build_ground_plans(fps, UnionParams{}, lod, problems, {}, nullptr);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_TRUE(plans[0].polygon.holes.empty());
  EXPECT_EQ(plans[0].members, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_NEAR(plans[0].area_m2, 100, 1e-9);
}

TEST(LodFilters, AnIslandTouchingItsHoleAtEveryVertexJoinsToo) {
  // A triangle wedged into a 2 x 2 hole with its three corners on the hole's sides: a plan of its own
  // (plans meet at points), none of its vertices strictly inside the hole. Found by fuzz_lod.
  auto fps = footprints_from_wkt({"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (4 4, 4 6, 6 6, 6 4, 4 4))",
                                  "POLYGON((5 4, 6 5, 4 5, 5 4))"});
  std::vector<Problem> problems;
  LodParams lod;
  lod.min_hole_area_m2 = 5;
  const auto exact = build_ground_plans(fps, UnionParams{}, problems);
  ASSERT_EQ(exact.size(), 2u);
  const auto plans = build_ground_plans(fps, UnionParams{}, lod, problems, {}, nullptr);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_TRUE(plans[0].polygon.holes.empty());
  EXPECT_EQ(plans[0].members, (std::vector<std::uint32_t>{0, 1}));
}

TEST(LodFilters, RasterModeFillsHolesThatHoldNoWholePixel) {
  // Holes 0.9 x 3 m (no 1 m pixel fits, whatever the grid's origin) and 2.5 x 2.5 m (a 1 m pixel
  // always fits): with 1 m pixels only the second stays; with 0.25 m pixels both stay.
  const auto fps = footprints_from_wkt(
      {"POLYGON((0 0, 20 0, 20 10, 0 10, 0 0), (2 2, 2 5, 2.9 5, 2.9 2, 2 2), (10 2, 10 4.5, 12.5 4.5, 12.5 2, 10 2))"});
  for (const double res : {1.0, 0.25}) {
    std::vector<Problem> problems;
    LodParams lod;
    lod.raster = true;
    UnionParams up;
    up.resolution_m = res;
    LodStats st;
    const auto plans = build_ground_plans(fps, up, lod, problems, {}, &st);
    ASSERT_EQ(plans.size(), 1u);
    EXPECT_EQ(st.raster_pixel_m, res);
    EXPECT_EQ(plans[0].polygon.holes.size(), res == 1.0 ? 1u : 2u) << res;
    EXPECT_EQ(st.raster_holes_filled, res == 1.0 ? 1u : 0u);
    EXPECT_EQ(count_code(problems, "HOLE_BELOW_PIXEL"), st.raster_holes_filled);
    if (res == 1.0) {
      EXPECT_NEAR(plans[0].area_m2, 200 - 6.25, 1e-9);
    }
  }
}

TEST(LodFilters, RasterModeSeesAnIslandBlockingEveryPixel) {
  // A 3 x 3 m hole with a 0.2 m wide cross of island walls through it: no 1 m pixel is empty, so
  // the paper's Update would not see the hole (it is filled, the islands join); with 0.5 m pixels it would.
  const auto fps = footprints_from_wkt({"POLYGON((0 0, 9 0, 9 9, 0 9, 0 0), (3 3, 3 6, 6 6, 6 3, 3 3))",
                                        "POLYGON((3.4 4.4, 5.6 4.4, 5.6 4.6, 3.4 4.6, 3.4 4.4))",
                                        "POLYGON((4.4 3.4, 4.6 3.4, 4.6 5.6, 4.4 5.6, 4.4 3.4))"});
  for (const double res : {1.0, 0.5}) {
    std::vector<Problem> problems;
    LodParams lod;
    lod.raster = true;
    UnionParams up;
    up.resolution_m = res;
    const auto plans = build_ground_plans(fps, up, lod, problems, {}, nullptr);
    if (res == 1.0) {
      ASSERT_EQ(plans.size(), 1u);
      EXPECT_TRUE(plans[0].polygon.holes.empty());
      EXPECT_EQ(plans[0].members.size(), 3u);
    } else {
      EXPECT_EQ(plans.size(), 2u);
      EXPECT_EQ(holes(plans), 1u);
    }
  }
}

TEST(LodFilters, BadValuesAreRefusedWithTheirName) {
  const auto fps = three();
  std::vector<Problem> problems;
  LodParams lod;
  lod.min_area_m2 = -1;
  try {
    build_ground_plans(fps, UnionParams{}, lod, problems);
    FAIL() << "negative min-area accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("min-area"), std::string::npos) << e.what();
  }
  lod = LodParams{};
  lod.close_gaps_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(build_ground_plans(fps, UnionParams{}, lod, problems), InvalidArgument);
}

TEST(LodFilters, PolygonAreaSubtractsHoles) {
  const auto fps = footprints_from_wkt({kCourtyard});
  EXPECT_DOUBLE_EQ(polygon_area(fps[0].polygons[0]), 300.0);
  // UTM-sized coordinates: about the first vertex, no cancellation
  Polygon p;
  p.outer = {{500000.0, 5000000.0}, {500000.1, 5000000.0}, {500000.1, 5000000.1}, {500000.0, 5000000.1}};
  // the coordinates are not exactly .1 apart: the expected area from the exact differences
  EXPECT_NEAR(polygon_area(p), (500000.1 - 500000.0) * (5000000.1 - 5000000.0), 1e-15);
}

}  // namespace
}  // namespace groundplan

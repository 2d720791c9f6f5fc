// SPDX-License-Identifier: MIT
// build_ground_plans is total (issue 20): any input is answered with plans and problems, never a
// crash, undefined behaviour or a hang. Each hostile value sits in one footprint next to ordinary
// ones: that footprint is a Problem naming it, the others are computed as usual. Also run under
// ASan/UBSan (packaging/run-sanitizer-tests.sh).
#include <gtest/gtest.h>

#include <groundplan/ground_plans.h>
#include <groundplan/level_of_detail.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "union_test_util.h"

namespace groundplan {
namespace {

using testing::footprint_from_wkt;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSub = std::numeric_limits<double>::denorm_min();

Footprint square(double x0, double y0, double side, const std::string& id) {
  Footprint f;
  f.source_id = id;
  f.polygons.push_back(Polygon{{{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}}, {}});
  return f;
}

/// Two ordinary squares (ids "a", "b", touching along a wall: one plan of area 200) and `bad`.
struct Outcome {
  std::vector<GroundPlan> plans;
  std::vector<Problem> problems;
};
Outcome run_with(const Footprint& bad, bool with_lod = false) {
  std::vector<Footprint> fps{square(0, 0, 10, "a"), bad, square(10, 0, 10, "b")};
  Outcome o;
  UnionParams up;
  up.threads = 1;
  if (with_lod) {
    LodParams lod;
    lod.snap_m = 0.01;
    lod.min_hole_area_m2 = 1;
    lod.raster = true;
    o.plans = build_ground_plans(fps, up, lod, o.problems);
  } else {
    o.plans = build_ground_plans(fps, up, o.problems);
  }
  return o;
}

/// The ordinary squares came out as one plan of members {0, 2}; `bad` is exactly one problem.
void expect_refused(const Footprint& bad, const std::string& code, const std::string& in_reason = "") {
  for (bool lod : {false, true}) {
    SCOPED_TRACE(lod ? "with level of detail" : "exact union");
    const Outcome o = run_with(bad, lod);
    ASSERT_EQ(o.plans.size(), 1u);
    EXPECT_EQ(o.plans[0].members, (std::vector<std::uint32_t>{0, 2}));
    EXPECT_NEAR(o.plans[0].area_m2, 200.0, 1e-9);
    ASSERT_EQ(o.problems.size(), 1u);
    EXPECT_EQ(o.problems[0].source_id, bad.source_id);
    EXPECT_EQ(o.problems[0].stage, "union");
    EXPECT_EQ(o.problems[0].code, code) << o.problems[0].reason;
    EXPECT_NE(o.problems[0].reason.find(in_reason), std::string::npos) << o.problems[0].reason;
  }
}

TEST(UnionTotalApi, NaNCoordinate) {
  Footprint f = square(30, 0, 5, "nan");
  f.polygons[0].outer[2].y = kNaN;
  expect_refused(f, "NOT_FINITE", "vertex 3 has y = nan");
}

TEST(UnionTotalApi, NaNInAHoleOnly) {
  Footprint f = square(30, 0, 5, "nan-hole");
  f.polygons[0].holes.push_back({{31, 1}, {kNaN, 1}, {32, 2}});
  expect_refused(f, "NOT_FINITE", "hole 1, vertex 2 has x = nan");
}

TEST(UnionTotalApi, Infinities) {
  for (double v : {kInf, -kInf}) {
    Footprint f = square(30, 0, 5, "inf");
    f.polygons[0].outer[1].x = v;
    expect_refused(f, "NOT_FINITE", "inf");
  }
}

TEST(UnionTotalApi, HugeCoordinates) {
  for (double v : {1e300, -1e300, std::numeric_limits<double>::max(), 0x1p50 * 1.5}) {
    Footprint f = square(30, 0, 5, "huge");
    f.polygons[0].outer[0].x = v;
    expect_refused(f, "COORDINATE_OUT_OF_RANGE");
  }
  // a whole footprint far out, alone: no plan, one problem
  std::vector<Footprint> fps{square(1e300, 1e300, 1e299, "far")};
  std::vector<Problem> problems;
  EXPECT_TRUE(build_ground_plans(fps, UnionParams{}, problems).empty());
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].code, "COORDINATE_OUT_OF_RANGE");
}

TEST(UnionTotalApi, SubnormalCoordinates) {
  for (double v : {kSub, -kSub, std::numeric_limits<double>::min(), 1e-200}) {
    Footprint f;
    f.source_id = "tiny";
    f.polygons.push_back(Polygon{{{0, 0}, {v, 0}, {v, v}, {0, v}}, {}});
    expect_refused(f, "COORDINATE_OUT_OF_RANGE", "2^-150");
  }
}

TEST(UnionTotalApi, EdgesOfTheAdmittedRangeAreComputedExactly) {
  // magnitudes 2^-150 and 2^50 are admitted: squares there come out whole. Each block is snap-rounded on
  // the grid of its own magnitude (16 ulp: 2 m at 2^49, 1e-322 at 2^-149), so the tiny squares keep their
  // size beside the far one; a square narrower than its grid collapses, and is reported as such.
  const double lo = 0x1p-150, hi = 0x1p49;
  std::vector<Footprint> fps{square(0, 0, lo, "lo"), square(lo, 0, lo, "lo2"), square(hi, hi, 64.0, "hi"),
                             square(-hi, hi, 1.0, "narrower-than-its-grid")};
  std::vector<Problem> problems;
  const auto plans = build_ground_plans(fps, UnionParams{}, problems);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].source_id, "narrower-than-its-grid");
  EXPECT_EQ(problems[0].code, "NO_AREA");
  EXPECT_NE(problems[0].reason.find("narrower than the snap-rounding grid"), std::string::npos) << problems[0].reason;
  EXPECT_NE(problems[0].reason.find("(2 m,"), std::string::npos) << problems[0].reason;
  ASSERT_EQ(plans.size(), 2u);
  std::size_t lo_plan = plans[0].members.size() == 2 ? 0 : 1;
  EXPECT_EQ(plans[lo_plan].members, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(plans[lo_plan].polygon.outer.size(), 4u);
  EXPECT_EQ(plans[lo_plan].area_m2, 2 * lo * lo);
  EXPECT_EQ(plans[1 - lo_plan].members, std::vector<std::uint32_t>{2});
  EXPECT_EQ(plans[1 - lo_plan].area_m2, 4096.0);
}

TEST(UnionTotalApi, EmptyFootprints) {
  Footprint none;
  none.source_id = "no-polygons";
  expect_refused(none, "NO_AREA");
  Footprint empty_rings;
  empty_rings.source_id = "empty-rings";
  empty_rings.polygons.push_back(Polygon{{}, {{}, {}}});
  empty_rings.polygons.emplace_back();
  expect_refused(empty_rings, "NO_AREA");
}

TEST(UnionTotalApi, OneAndTwoPointRings) {
  Footprint one;
  one.source_id = "one-point";
  one.polygons.push_back(Polygon{{{40, 40}}, {{{41, 41}}}});
  expect_refused(one, "NO_AREA");
  Footprint two;
  two.source_id = "two-points";
  two.polygons.push_back(Polygon{{{40, 40}, {45, 45}}, {}});
  expect_refused(two, "NO_AREA");
  // as holes of an ordinary square they are no holes (even-odd: a 2-point ring retraces one edge)
  Footprint with_holes = square(0, 20, 10, "degenerate-holes");
  with_holes.polygons[0].holes = {{{5, 25}}, {{2, 22}, {8, 28}}, {}};
  std::vector<Problem> problems;
  const auto plans = build_ground_plans({with_holes}, UnionParams{}, problems);
  EXPECT_TRUE(problems.empty());
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_TRUE(plans[0].polygon.holes.empty());
  EXPECT_EQ(plans[0].area_m2, 100.0);
}

TEST(UnionTotalApi, AMillionRepeatedPoints) {
  // an ordinary square whose second corner is written a million times
  Footprint f = square(30, 0, 5, "repeated");
  f.polygons[0].outer.insert(f.polygons[0].outer.begin() + 1, 1000000, Point2{35, 0});
  // a ring of one point written a million times
  Footprint g;
  g.source_id = "one-point-repeated";
  g.polygons.push_back(Polygon{Ring(1000000, Point2{50, 50}), {}});
  std::vector<Problem> problems;
  const auto plans = build_ground_plans({square(0, 0, 10, "a"), f, g}, UnionParams{}, problems);
  ASSERT_EQ(plans.size(), 2u);
  const GroundPlan& p = plans[0].members == std::vector<std::uint32_t>{1} ? plans[0] : plans[1];
  EXPECT_EQ(p.members, std::vector<std::uint32_t>{1});
  EXPECT_EQ(p.polygon.outer.size(), 4u);
  EXPECT_EQ(p.area_m2, 25.0);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].source_id, "one-point-repeated");
  EXPECT_EQ(problems[0].code, "NO_AREA");
}

TEST(UnionTotalApi, EveryHostileValueAtOnce) {
  // all of the above in one call, several polygons per footprint: one problem each, no plan lost
  std::vector<Footprint> fps;
  const double values[] = {kNaN, kInf, -kInf, 1e300, -1e300, kSub, -kSub};
  for (std::size_t i = 0; i < std::size(values); ++i) {
    Footprint f = square(20.0 * static_cast<double>(i), 0, 10, "ok" + std::to_string(i));
    fps.push_back(f);
    f.source_id = "bad" + std::to_string(i);
    f.polygons.push_back(f.polygons[0]);
    f.polygons[1].outer[3] = Point2{values[i], values[i]};
    fps.push_back(f);
  }
  std::vector<Problem> problems;
  UnionParams up;
  up.threads = 2;
  const auto plans = build_ground_plans(fps, up, problems);
  EXPECT_EQ(plans.size(), std::size(values));
  for (const GroundPlan& g : plans) EXPECT_EQ(g.area_m2, 100.0);
  ASSERT_EQ(problems.size(), std::size(values));
  for (std::size_t i = 0; i < problems.size(); ++i) EXPECT_EQ(problems[i].source_id, "bad" + std::to_string(i));
}

}  // namespace
}  // namespace groundplan

// SPDX-License-Identifier: MIT
// --snap and --simplify (issue 9) on random cities, GEOS as the judge: every plan valid (isValid),
// no two plans overlapping, every simplified ring within T of its input ring (Hausdorff distance).
#include <gtest/gtest.h>

#include <geos_c.h>
#include <groundplan/level_of_detail.h>

#include <random>
#include <string>

#include "union_generators.h"
#include "union_test_util.h"

namespace groundplan {
namespace {

std::vector<GroundPlan> plans_of(const std::vector<Footprint>& fps) {
  std::vector<Problem> problems;
  UnionParams params;
  params.threads = 1;
  params.device = Device::Cpu;
  return build_ground_plans(fps, params, problems);
}

/// The synthetic city with every vertex shaken by up to `amount` in x and y: walls that were shared
/// become near misses and slight overlaps, so the union has noisy walls, slivers and small holes.
std::vector<Footprint> shaken_city(std::size_t n, std::uint64_t seed, double amount) {
  auto city = testing::synthetic_city(n, seed);
  testing::Rng rng(seed * 31 + 7);
  std::uniform_real_distribution<double> shake(-amount, amount);
  for (auto& f : city)
    for (auto& p : f.polygons) {
      for (auto& q : p.outer) q = {q.x + shake(rng), q.y + shake(rng)};
      for (auto& h : p.holes)
        for (auto& q : h) q = {q.x + shake(rng), q.y + shake(rng)};
    }
  return city;
}

struct Geos {
  GEOSContextHandle_t h = GEOS_init_r();
  ~Geos() { GEOS_finish_r(h); }
};

GEOSGeometry* line_of(GEOSContextHandle_t h, const Ring& r) {
  GEOSCoordSequence* s = GEOSCoordSeq_create_r(h, static_cast<unsigned>(r.size() + 1), 2);
  for (std::size_t i = 0; i <= r.size(); ++i)
    GEOSCoordSeq_setXY_r(h, s, static_cast<unsigned>(i), r[i % r.size()].x, r[i % r.size()].y);
  return GEOSGeom_createLineString_r(h, s);
}

/// Hausdorff distance of two closed rings, by GEOS with every edge densified into 8 pieces.
double hausdorff(GEOSContextHandle_t h, const Ring& a, const Ring& b) {
  GEOSGeometry* ga = line_of(h, a);
  GEOSGeometry* gb = line_of(h, b);
  double d = -1;
  GEOSHausdorffDistanceDensify_r(h, ga, gb, 0.125, &d);
  GEOSGeom_destroy_r(h, ga);
  GEOSGeom_destroy_r(h, gb);
  return d;
}

std::size_t vertices(const std::vector<GroundPlan>& plans) {
  std::size_t n = 0;
  for (const auto& p : plans) {
    n += p.polygon.outer.size();
    for (const auto& r : p.polygon.holes) n += r.size();
  }
  return n;
}

class LodSimplifyCity : public ::testing::TestWithParam<double> {};

TEST_P(LodSimplifyCity, ValidNonOverlappingAndWithinTolerance) {
  const double tol = GetParam();
  for (std::uint64_t seed : {3u, 8u}) {
    const auto fps = shaken_city(800, seed, 0.05);
    const auto plans = plans_of(fps);
    LodStats stats;
    const auto out = simplify_plans(plans, tol, &stats);
    const std::string where = "T " + std::to_string(tol) + " seed " + std::to_string(seed);
    ASSERT_EQ(out.size(), plans.size()) << where;
    EXPECT_EQ(stats.simplify_vertices_before, vertices(plans)) << where;
    EXPECT_EQ(stats.simplify_vertices_after, vertices(out)) << where;
    EXPECT_LT(stats.simplify_vertices_after, stats.simplify_vertices_before) << where;
    // GEOS: validity of each plan and overlaps between plans (ours against our input plans).
    const auto cmp = gis::compare_with_geos(fps, out, &plans);
    EXPECT_EQ(cmp.invalid_ours, 0u) << where << ": " << cmp.first_invalid_reason;
    EXPECT_EQ(cmp.overlapping_ours, 0u) << where;
    EXPECT_EQ(cmp.polygons_ours, cmp.polygons_geos) << where;
    EXPECT_EQ(cmp.holes_ours, cmp.holes_geos) << where;
    Geos g;
    double worst = 0;
    for (std::size_t p = 0; p < plans.size(); ++p) {
      EXPECT_EQ(out[p].members, plans[p].members);
      EXPECT_NEAR(out[p].area_m2, polygon_area(out[p].polygon), 1e-9 * (1 + out[p].area_m2));
      ASSERT_EQ(out[p].polygon.holes.size(), plans[p].polygon.holes.size());
      worst = std::max(worst, hausdorff(g.h, plans[p].polygon.outer, out[p].polygon.outer));
      for (std::size_t k = 0; k < plans[p].polygon.holes.size(); ++k)
        worst = std::max(worst, hausdorff(g.h, plans[p].polygon.holes[k], out[p].polygon.holes[k]));
    }
    EXPECT_LE(worst, tol * (1 + 1e-9)) << where;
    EXPECT_GT(worst, tol * 0.1) << where;  // it did simplify up to about the tolerance
  }
}

INSTANTIATE_TEST_SUITE_P(Tolerances, LodSimplifyCity, ::testing::Values(0.01, 0.1, 1.0));

TEST(LodSnapCity, SnappedShakenCityUnitesIntoValidPlans) {
  // 1 cm shake, 3 cm snap: every shared corner, now up to 2.9 cm from its copies, is shared again.
  // The union of the snapped footprints agrees with GEOS and has about the unshaken city's plans.
  const auto fps = shaken_city(800, 5, 0.01);
  LodStats stats;
  const auto snapped = snap_footprints(fps, 0.03, &stats);
  EXPECT_GT(stats.snap_vertices_moved, 200u);
  EXPECT_GT(stats.snap_vertices_inserted, 200u);
  const auto before = plans_of(fps);
  const auto c = testing::run_and_compare(snapped, 1, 1e-9, testing::Oracle::AreaAndValid);
  EXPECT_TRUE(c.ok) << c.message.substr(0, 2000);
  EXPECT_EQ(c.cmp.invalid_ours, 0u);
  EXPECT_EQ(c.cmp.overlapping_ours, 0u);
  std::size_t holes_before = 0;
  for (const auto& p : before) holes_before += p.polygon.holes.size();
  // The shake split 244 plans into 369; snapping brings back (about) the unshaken city's plans.
  const auto exact = plans_of(testing::synthetic_city(800, 5));
  EXPECT_GT(before.size(), exact.size() + 100);
  EXPECT_LE(c.cmp.polygons_ours, exact.size() + 5);
  EXPECT_LE(c.cmp.holes_ours, holes_before);
}

}  // namespace
}  // namespace groundplan

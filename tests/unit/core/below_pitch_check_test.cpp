// SPDX-License-Identifier: MIT
// The comparison with GEOS where counts differ (gis/geosref/below_pitch.*, issue 20): a difference is a match
// only where it is a gap, neck or hole narrower than the snap pitch. Hand-made plans against GEOS's union of
// hand-made footprints, each once with a feature below the pitch and once with the same feature far wider
// (still within the area tolerance, so that only the count check decides).
#include <gtest/gtest.h>

#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <vector>

namespace groundplan {
namespace {

Ring box(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }
Footprint fp(std::vector<Polygon> polys) {
  Footprint f;
  f.polygons = std::move(polys);
  return f;
}
GroundPlan plan(Polygon p) {
  GroundPlan g;
  g.polygon = std::move(p);
  return g;
}

// Coordinates up to 10: the pitch is 16 ulp(10) = 2^-45 = 2.8e-14 m; a difference up to 1.5 pitches is below it.
constexpr double kBelow = 1e-14, kWide = 1e-9;

TEST(BelowPitchCheck, ThePitchIsSixteenUlpsOfTheLargestCoordinate) {
  EXPECT_EQ(snap_pitch(10.0), 0x1p-45);
  EXPECT_EQ(snap_pitch(5400000.0), 0x1p-26);
}

TEST(BelowPitchCheck, TwoPolygonsJoinedAcrossAGapNarrowerThanThePitch) {
  for (const double gap : {kBelow, kWide}) {
    const std::vector<Footprint> fps{fp({Polygon{box(0, 0, 5, 5), {}}}), fp({Polygon{box(5 + gap, 0, 10, 5), {}}})};
    const std::vector<GroundPlan> ours{plan(Polygon{box(0, 0, 10, 5), {}})};
    const gis::GeosComparison c = gis::compare_with_geos(fps, ours);
    ASSERT_EQ(c.polygons_geos, 2u) << c.summary();
    EXPECT_FALSE(c.counts_exact());
    EXPECT_TRUE(c.differences_checked);
    EXPECT_EQ(c.below_pitch(), gap == kBelow) << c.summary();
    EXPECT_EQ(c.matches(1e-9), gap == kBelow) << c.summary();
  }
}

TEST(BelowPitchCheck, AHoleNarrowerThanThePitchCollapsed) {
  for (const double h : {kBelow, kWide}) {
    const std::vector<Footprint> fps{fp({Polygon{box(0, 0, 10, 10), {box(2, 5, 8, 5 + h)}}})};
    const std::vector<GroundPlan> ours{plan(Polygon{box(0, 0, 10, 10), {}})};
    const gis::GeosComparison c = gis::compare_with_geos(fps, ours);
    ASSERT_EQ(c.holes_geos, 1u) << c.summary();
    EXPECT_EQ(c.matches(1e-9), h == kBelow) << c.summary();
    if (h == kWide) {
      EXPECT_NE(c.first_difference_not_below_pitch.find("near (5 5"), std::string::npos) << c.summary();
    }
  }
}

TEST(BelowPitchCheck, AHoleClosedOffByGapsNarrowerThanThePitch) {
  // a frame of four bars; the right bar stands off the others by `gap` at both ends: GEOS gives two polygons
  // and no hole (the yard reaches the outside through the gaps); closing the gaps makes one frame with a hole
  for (const double gap : {kBelow, kWide}) {
    const std::vector<Footprint> fps{fp({Polygon{box(0, 0, 10, 1), {}}}), fp({Polygon{box(0, 9, 10, 10), {}}}),
                                     fp({Polygon{box(0, 1, 1, 9), {}}}), fp({Polygon{box(9, 1 + gap, 10, 9 - gap), {}}})};
    const std::vector<GroundPlan> ours{plan(Polygon{box(0, 0, 10, 10), {{{1, 1}, {1, 9}, {9, 9}, {9, 1}}}})};
    const gis::GeosComparison c = gis::compare_with_geos(fps, ours);
    ASSERT_EQ(c.polygons_geos, 2u) << c.summary();
    ASSERT_EQ(c.holes_geos, 0u) << c.summary();
    EXPECT_EQ(c.matches(1e-9), gap == kBelow) << c.summary();
  }
}

TEST(BelowPitchCheck, APolygonSplitAtANeckNarrowerThanThePitch) {
  // GEOS: one polygon, two squares joined by a neck of width `w`; ours: the two squares, touching at a corner
  for (const double w : {kBelow, kWide}) {
    // a square 0..5 below, a square 5-w..10 above: they overlap in a w x w square at (5, 5)
    const std::vector<Footprint> fps{fp({Polygon{box(0, 0, 5, 5), {}}}), fp({Polygon{box(5 - w, 5 - w, 10, 10), {}}})};
    const std::vector<GroundPlan> ours{plan(Polygon{box(0, 0, 5, 5), {}}), plan(Polygon{box(5, 5, 10, 10), {}})};
    const gis::GeosComparison c = gis::compare_with_geos(fps, ours);
    ASSERT_EQ(c.polygons_geos, 1u) << c.summary();
    EXPECT_EQ(c.matches(1e-9), w == kBelow) << c.summary();
  }
}

TEST(BelowPitchCheck, EqualCountsNeedNoCheck) {
  const std::vector<Footprint> fps{fp({Polygon{box(0, 0, 5, 5), {}}})};
  const gis::GeosComparison c = gis::compare_with_geos(fps, {plan(Polygon{box(0, 0, 5, 5), {}})});
  EXPECT_TRUE(c.matches(1e-9));
  EXPECT_FALSE(c.differences_checked);
}

}  // namespace
}  // namespace groundplan

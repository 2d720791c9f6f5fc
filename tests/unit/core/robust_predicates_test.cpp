// SPDX-License-Identifier: MIT
// The adaptive predicates of core/src/robust (paper §6.3): exact signs where naive double arithmetic
// is wrong, and escalation to a higher rung only when the lower one cannot certify.
#include <gtest/gtest.h>

#include <cmath>

#include "robust/predicates.h"

namespace groundplan::robust {
namespace {

double naive_orient(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

TEST(RobustPredicates, EasyOrientationStaysInDouble) {
  reset_rung_stats();
  EXPECT_EQ(orient({0, 0}, {1, 0}, {0, 1}), 1);
  EXPECT_EQ(orient({0, 0}, {1, 0}, {0, -1}), -1);
  EXPECT_EQ(orient({5e6, 3e6}, {5e6 + 10, 3e6}, {5e6 + 3, 3e6 + 0.001}), 1);
  const RungStats s = rung_stats();
  EXPECT_EQ(s.at(Family::Cross, 0), 3u);
  EXPECT_EQ(s.at(Family::Cross, 1), 0u);
  EXPECT_EQ(s.at(Family::Cross, 2), 0u);
}

TEST(RobustPredicates, NaiveDoubleGetsTheSignWrongWeDoNot) {
  // a is 4.6e-15 and 5.3e-15 off the line y = x through b and c: exactly, it lies left of b->c ...
  const Point2 a{0.5000000000000046, 0.5000000000000053}, b{12, 12}, c{24, 24};
  ASSERT_LT(naive_orient(a, b, c), 0);  // ... but naive double says right (checked with exact rationals)
  reset_rung_stats();
  EXPECT_EQ(orient(a, b, c), 1);
  EXPECT_EQ(orient(b, c, a), 1);  // cyclic
  EXPECT_EQ(orient(a, c, b), -1);
  const RungStats s = rung_stats();
  EXPECT_EQ(s.at(Family::Cross, 0), 0u) << "the double filter must not certify a wrong sign";
  EXPECT_EQ(s.at(Family::Cross, 1) + s.at(Family::Cross, 2), 3u);
}

TEST(RobustPredicates, ExactZeroIsCertifiedWithoutMpfrWhenDifferencesAreExact) {
  reset_rung_stats();
  EXPECT_EQ(orient({0.5, 0.5}, {1.5, 1.5}, {2.5, 2.5}), 0);
  // a party wall of a block rotated by the integer matrix (3 -4; 4 3) on dyadic coordinates
  EXPECT_EQ(orient({3 * 1.125 - 4 * 2.5, 4 * 1.125 + 3 * 2.5}, {3 * 7.25 - 4 * 2.5, 4 * 7.25 + 3 * 2.5},
                   {3 * 4.0625 - 4 * 2.5, 4 * 4.0625 + 3 * 2.5}),
            0);
  const RungStats s = rung_stats();
  EXPECT_EQ(s.at(Family::Cross, 2), 0u);
}

TEST(RobustPredicates, MpfrOnlyWhenDifferencesAreInexactAndTheBoundFails) {
  // b - a is not a double (1 - 2^-80), and c is exactly on the line: only MPFR can say 0.
  const Point2 a{std::ldexp(1.0, -80), std::ldexp(1.0, -80)}, b{1, 1}, c{2, 2};
  reset_rung_stats();
  EXPECT_EQ(orient(a, b, c), 0);
  EXPECT_EQ(rung_stats().at(Family::Cross, 2), 1u);
  // a hair off the line: decided below MPFR
  reset_rung_stats();
  EXPECT_EQ(orient(a, b, {2, std::nextafter(2.0, 3.0)}), 1);
  EXPECT_EQ(rung_stats().at(Family::Cross, 2), 0u);
}

TEST(RobustPredicates, CrossSignOfFourPoints) {
  EXPECT_EQ(cross_sign({0, 0}, {1, 0}, {5, 5}, {5, 6}), 1);
  EXPECT_EQ(cross_sign({0, 0}, {1, 0}, {5, 5}, {7, 5}), 0);
  EXPECT_EQ(cross_sign({0, 0}, {1, 0}, {5, 5}, {5, 4}), -1);
}

TEST(RobustPredicates, CompareCrossingsOrdersAlongTheSegment) {
  const Point2 a{0, 0}, b{10, 0};
  // f crosses at x = 3, g at x = 7
  EXPECT_EQ(compare_crossings(a, b, {3, -1}, {3, 1}, {7, 1}, {7, -1}), -1);
  EXPECT_EQ(compare_crossings(a, b, {7, 1}, {7, -1}, {3, -1}, {3, 1}), 1);
  // same point, different lines: an exact tie
  reset_rung_stats();
  EXPECT_EQ(compare_crossings(a, b, {5, -1}, {5, 1}, {4, -1}, {6, 1}), 0);
  EXPECT_EQ(rung_stats().at(Family::CompareCrossings, 0), 0u);
  // valid for crossings outside the segment too (events reused on collinear segments)
  EXPECT_EQ(compare_crossings(a, b, {-3, -1}, {-3, 1}, {13, -1}, {13, 1}), -1);
}

TEST(RobustPredicates, CompareCrossingsOneUlpApartAtProjectedCoordinates) {
  // crossings half an ulp apart (4.7e-10 m) on a segment at ~5e6 m: still decided, and correctly
  const Point2 a{5000000.0, 3000000.0}, b{5000010.0, 3000000.0};
  const double x = 5000004.0;
  const Point2 f0{x, 2999999.0}, f1{x, 3000001.0};
  const Point2 g0{x, 2999999.0}, g1{std::nextafter(x, 1e9), 3000001.0};  // leans right by one ulp
  EXPECT_EQ(compare_crossings(a, b, f0, f1, g0, g1), -1);
  EXPECT_EQ(compare_crossings(a, b, g0, g1, f0, f1), 1);
}

TEST(RobustPredicates, ExactTieOfCrossingsEscalatesToTheLastRung) {
  // three lines through one point that is not a vertex: no filter can certify a zero
  const Point2 a{5000000.0, 3000000.0}, b{5000010.0, 3000010.0};
  reset_rung_stats();
  EXPECT_EQ(compare_crossings(a, b, {5000004.0, 3000000.0}, {5000006.0, 3000010.0}, {5000000.0, 3000010.0},
                              {5000010.0, 3000000.0}),
            0);
  const RungStats s = rung_stats();
  EXPECT_EQ(s.at(Family::CompareCrossings, 0), 0u);
  EXPECT_EQ(s.at(Family::CompareCrossings, 1), 0u);
  EXPECT_EQ(s.at(Family::CompareCrossings, 2), 1u);
}

TEST(RobustPredicates, TieOfCrossingsOnOneLineIsCertifiedWithoutMpfr) {
  // The shadow of a triangulated model (kml-collada-macky-google): one edge of two facets, once each
  // way, and a piece of the same line. Both cross a->b at one point; no filter can certify the zero,
  // two exact orientations can.
  const Point2 a{476737.1016862634, 4428897.4633007497}, b{476736.66929938842, 4428933.5569486981};
  const Point2 f0{476743.939623432, 4428897.5452279719}, f1{476737.10164363409, 4428897.4633117458};
  reset_rung_stats();
  EXPECT_EQ(compare_crossings(a, b, f0, f1, f0, f1), 0);
  EXPECT_EQ(compare_crossings(a, b, f0, f1, f1, f0), 0);
  const Point2 mid{(f0.x + f1.x) / 2, (f0.y + f1.y) / 2};
  if (orient(f0, f1, mid) == 0) {
    EXPECT_EQ(compare_crossings(a, b, f0, f1, mid, f1), 0);
  }
  const RungStats s = rung_stats();
  EXPECT_EQ(s.at(Family::CompareCrossings, 2), 0u);
  EXPECT_GE(s.at(Family::CompareCrossings, 1), 2u);
  // Not on one line, crossing a->b at one point: still the last rung (the shortcut must not fire).
  reset_rung_stats();
  const Point2 c{5000000.0, 3000000.0}, d{5000010.0, 3000010.0};
  EXPECT_EQ(compare_crossings(c, d, {5000004.0, 3000000.0}, {5000006.0, 3000010.0}, {5000000.0, 3000010.0},
                              {5000010.0, 3000000.0}),
            0);
  EXPECT_EQ(rung_stats().at(Family::CompareCrossings, 2), 1u);
}

TEST(RobustPredicates, NearestCrossingsByVisibilityBisection) {
  const Point2 a{0, 0}, b{100, 0};
  std::vector<Segment> segs;
  for (int i = 99; i >= 1; --i) segs.push_back({{static_cast<double>(i), -1}, {static_cast<double>(i) + 0.5, 1}});
  reset_rung_stats();
  const auto near = nearest_crossings(a, b, segs);
  ASSERT_EQ(near.size(), 1u);
  EXPECT_EQ(near[0], 98u);  // the segment at x = 1
  const RungStats s = rung_stats();
  EXPECT_GT(s.at(Family::Visibility, 0), 0u);
  EXPECT_EQ(s.at(Family::CompareCrossings, 2), 0u) << "well separated: no MPFR";
}

TEST(RobustPredicates, NearestCrossingsReturnsAllTied) {
  const Point2 a{0, 0}, b{10, 0};
  const std::vector<Segment> segs{{{5, -1}, {5, 1}}, {{4, -1}, {6, 1}}, {{7, -1}, {7, 1}}, {{6, 1}, {4, -1}}};
  const auto near = nearest_crossings(a, b, segs);
  EXPECT_EQ(near, (std::vector<std::size_t>{0, 1, 3}));
}

TEST(RobustPredicates, NearestCrossingsSeparatesCrossingsOneUlpApart) {
  const Point2 a{0, 0}, b{1, 0};
  const double x = 0.5, x1 = std::nextafter(0.5, 1.0);
  const std::vector<Segment> segs{{{x1, -1}, {x1, 1}}, {{x, -1}, {x, 1}}};
  EXPECT_EQ(nearest_crossings(a, b, segs), std::vector<std::size_t>{1});
}

TEST(RobustPredicates, CrossingPointIsInsideBothBoxes) {
  const Point2 p = crossing_point({0, 0}, {10, 10}, {0, 10}, {10, 0});
  EXPECT_DOUBLE_EQ(p.x, 5);
  EXPECT_DOUBLE_EQ(p.y, 5);
  const Point2 q = crossing_point({5e6, 3e6}, {5e6 + 10, 3e6 + 1e-3}, {5e6 + 4, 3e6 - 1}, {5e6 + 4, 3e6 + 1});
  EXPECT_EQ(q.x, 5e6 + 4);
  EXPECT_GE(q.y, 3e6);
  EXPECT_LE(q.y, 3e6 + 1e-3);
}

}  // namespace
}  // namespace groundplan::robust

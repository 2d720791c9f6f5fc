// SPDX-License-Identifier: MIT
// One crossing, one rounding (issue 20): robust::crossing_point depends on the two segments only, not
// on which is asked first or on their directions. Before, the walk rounded a crossing it met along
// either edge to two doubles a few ulps apart, and plans overlapped by a sliver there
// (tests/corpus/fuzz-regressions/union/plans-overlap-self-intersecting-*).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include <mpfr.h>

#include "robust/predicates.h"

namespace groundplan {
namespace {

TEST(CrossingPoint, SameDoublesInEveryOperandOrder) {
  for (const double offset : {0.0, 5e5}) {
    std::mt19937_64 rng(20);
    std::uniform_int_distribution<int> lattice(0, 255);
    int crossings = 0, differing = 0;
    for (int i = 0; i < 100000; ++i) {
      auto pt = [&] { return Point2{offset + lattice(rng) / 7.0, offset + lattice(rng) / 11.0}; };
      const Point2 a = pt(), b = pt(), c = pt(), d = pt();
      // proper crossings only (the function's precondition)
      if (robust::orient(a, b, c) * robust::orient(a, b, d) >= 0 ||
          robust::orient(c, d, a) * robust::orient(c, d, b) >= 0)
        continue;
      ++crossings;
      const Point2 p = robust::crossing_point(a, b, c, d);
      for (const Point2& q : {robust::crossing_point(b, a, c, d), robust::crossing_point(a, b, d, c),
                              robust::crossing_point(c, d, a, b), robust::crossing_point(d, c, b, a)})
        differing += !(p == q);
    }
    EXPECT_GT(crossings, 10000);
    EXPECT_EQ(differing, 0) << "of " << crossings << " crossings at offset " << offset;
  }
}

/// Three or more edges through one crossing (a ring retracing an edge, collinear walls crossed by
/// one edge): every pair has the same exact point, so every pair must give the same doubles. Before
/// the correct rounding (issue 20), each pair's long-double arithmetic was rounded on its own and
/// pairs disagreed by an ulp (union-open a676fee0: three edges through one crossing, plans overlapping
/// next to two output vertices one ulp apart; 3d0458f6: an edge retraced three times).
TEST(CrossingPoint, ConcurrentEdgesGiveOnePoint) {
  for (const double offset : {0.0, 5e5}) {
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<int> lattice(0, 255);
    int crossings = 0, differing = 0;
    for (int i = 0; i < 100000; ++i) {
      const int ax = lattice(rng), ay = lattice(rng), bx = lattice(rng), by = lattice(rng);
      // a, b, b2 = a + 2 (b - a) in quarters (exact doubles, exactly collinear), c, d in sevenths/elevenths
      auto quarter = [&](int x, int y) { return Point2{offset + x / 4.0, offset + y / 4.0}; };
      auto odd = [&](int x, int y) { return Point2{offset + x / 7.0, offset + y / 11.0}; };
      const Point2 a = quarter(ax, ay), b = quarter(bx, by), b2 = quarter(2 * bx - ax, 2 * by - ay);
      const Point2 c = odd(lattice(rng), lattice(rng)), d = odd(lattice(rng), lattice(rng));
      if (robust::orient(a, b, c) * robust::orient(a, b, d) >= 0 ||
          robust::orient(c, d, a) * robust::orient(c, d, b) >= 0 || robust::orient(a, b, b2) != 0)
        continue;
      ++crossings;
      const Point2 p = robust::crossing_point(a, b, c, d);
      differing += !(p == robust::crossing_point(a, b2, c, d)) || !(p == robust::crossing_point(d, c, b2, a));
    }
    EXPECT_GT(crossings, 5000);
    EXPECT_EQ(differing, 0) << "of " << crossings << " crossings at offset " << offset;
  }
}

/// The point is the exact crossing correctly rounded (to nearest, ties to even), checked against exact
/// rational arithmetic on quarter-integer coordinates at a projected offset.
TEST(CrossingPoint, CorrectlyRounded) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::int64_t> lattice(0, 4000);
  const std::int64_t off4 = 4 * 500000;  // offset 5e5 in quarter units
  mpfr_t r;
  mpfr_init2(r, 53);
  mpfr_t n;
  mpfr_init2(n, 256);
  int crossings = 0, wrong = 0;
  for (int i = 0; i < 100000; ++i) {
    std::int64_t q[8];
    for (auto& v : q) v = lattice(rng);
    auto pt = [&](int k) { return Point2{(off4 + q[k]) / 4.0, (off4 + q[k + 1]) / 4.0}; };
    const Point2 a = pt(0), b = pt(2), c = pt(4), d = pt(6);
    if (robust::orient(a, b, c) * robust::orient(a, b, d) >= 0 ||
        robust::orient(c, d, a) * robust::orient(c, d, b) >= 0)
      continue;
    ++crossings;
    // in quarter units relative to the offset: t = oa / (oa - ob), exactly in integers
    const std::int64_t fx = q[6] - q[4], fy = q[7] - q[5];
    const std::int64_t oa = fx * (q[1] - q[5]) - fy * (q[0] - q[4]);
    const std::int64_t ob = fx * (q[3] - q[5]) - fy * (q[2] - q[4]);
    const std::int64_t den = oa - ob;
    const Point2 p = robust::crossing_point(a, b, c, d);
    for (int k = 0; k < 2; ++k) {
      // coordinate = ((off4 + a_k) den + oa (b_k - a_k)) / (4 den)
      const std::int64_t num = (off4 + q[k]) * den + oa * (q[2 + k] - q[k]);
      mpfr_set_sj(n, num, MPFR_RNDN);  // exact (256 bits)
      mpfr_div_si(r, n, 4 * den, MPFR_RNDN);
      wrong += mpfr_get_d(r, MPFR_RNDN) != (k == 0 ? p.x : p.y);
    }
  }
  mpfr_clear(r);
  mpfr_clear(n);
  EXPECT_GT(crossings, 10000);
  EXPECT_EQ(wrong, 0) << "coordinates not correctly rounded, of " << crossings << " crossings";
}

/// An exact crossing halfway between two doubles rounds to the even one (the long-double bound cannot
/// decide a tie, so this goes through the exact MPFR path).
TEST(CrossingPoint, TiesGoToEven) {
  const double u = std::ldexp(1.0, -52);
  // a->b crosses the x axis at x = 1 + u/2 (halfway between 1 and 1 + u): even is 1
  EXPECT_EQ(robust::crossing_point({1, -1}, {1 + u, 1}, {0, 0}, {4, 0}).x, 1.0);
  // at x = 1 + 3u/2 (halfway between 1 + u and 1 + 2u): even is 1 + 2u
  EXPECT_EQ(robust::crossing_point({1 + u, -1}, {1 + 2 * u, 1}, {0, 0}, {4, 0}).x, 1 + 2 * u);
  // the same in y, operands swapped
  EXPECT_EQ(robust::crossing_point({0, 0}, {0, 4}, {-1, 1 + u}, {1, 1 + 2 * u}).y, 1 + 2 * u);
}

}  // namespace
}  // namespace groundplan

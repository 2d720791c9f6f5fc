// SPDX-License-Identifier: MIT
// One crossing, one rounding (issue 20): robust::crossing_point depends on the two segments only, not
// on which is asked first or on their directions. Before, the walk rounded a crossing it met along
// either edge to two doubles a few ulps apart, and plans overlapped by a sliver there
// (tests/corpus/fuzz-regressions/union/plans-overlap-self-intersecting-*).
#include <gtest/gtest.h>

#include <random>

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

}  // namespace
}  // namespace groundplan

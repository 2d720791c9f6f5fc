// SPDX-License-Identifier: MIT
// Property tests of the union engine against GEOS UnaryUnion (issue 3): seeded random cases per
// degenerate family; every case must match (symmetric difference <= 1e-9 of the area, same
// numbers of polygons and holes, all valid, no overlaps). A failure prints the seed and the WKT:
// make it a named case in tests/unit/core/union_regression_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "robust/predicates.h"

#include "union_generators.h"
#include "union_test_util.h"

namespace groundplan {
namespace {

using testing::Family;

// Oracle policy. Every family is held to the strict DESIGN.md criterion except NearCollinear:
// there, walls that should coincide differ by less than one ulp after an inexact rotation, and the
// exact union has gaps and overlaps of ~1e-16 m between them. GEOS decides those inconsistently
// (its overlay falls back to snapping with a tolerance; its relate() reported an interior overlap
// for a pair whose corner lies 1.3e-14 outside the other, checked with exact rationals; and on
// seed 13000576 its union is 42 m2 off the even-odd union of the input, see
// UnionRegression.NearCollinearGeosSnapsWrongly). So that family asserts validity, and either
// GEOS's area, or agreement with an independent oracle: the exact even-odd membership of random
// points (robust predicates), which does not depend on GEOS. Counts there are reported only.
class UnionProperty : public ::testing::TestWithParam<Family> {};

/// Exact membership of p in the even-odd region of one polygon (perturbed ray to +x).
bool inside_even_odd(const Polygon& poly, const Point2& p) {
  bool odd = false;
  auto ring = [&](const Ring& r) {
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const Point2& a = r[i];
      const Point2& b = r[(i + 1) % n];
      const bool up = a.y < b.y;
      const Point2& lo = up ? a : b;
      const Point2& hi = up ? b : a;
      if (lo.y <= p.y && p.y < hi.y && robust::orient(lo, hi, p) > 0) odd = !odd;
    }
  };
  ring(poly.outer);
  for (const Ring& h : poly.holes) ring(h);
  return odd;
}

/// Random points where membership in the plans and in the union of the footprints differ.
int sampling_disagreements(const std::vector<Footprint>& fps, const std::vector<GroundPlan>& plans, int n,
                           std::uint64_t seed) {
  double minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
  for (const Footprint& f : fps)
    for (const Polygon& p : f.polygons)
      for (const Point2& q : p.outer) {
        minx = std::min(minx, q.x);
        miny = std::min(miny, q.y);
        maxx = std::max(maxx, q.x);
        maxy = std::max(maxy, q.y);
      }
  testing::Rng rng(seed);
  std::uniform_real_distribution<double> ux(minx, maxx), uy(miny, maxy);
  int bad = 0;
  for (int i = 0; i < n; ++i) {
    const Point2 p{ux(rng), uy(rng)};
    bool in_union = false, in_plans = false;
    for (const Footprint& f : fps)
      for (const Polygon& poly : f.polygons) in_union = in_union || inside_even_odd(poly, p);
    for (const GroundPlan& g : plans) in_plans = in_plans || inside_even_odd(g.polygon, p);
    bad += in_union != in_plans;
  }
  return bad;
}

constexpr int kCasesPerFamily = 1000;

TEST_P(UnionProperty, MatchesGeos) {
  const Family fam = GetParam();
  const auto oracle = fam == Family::NearCollinear ? testing::Oracle::AreaAndValid : testing::Oracle::Strict;
  int failures = 0, count_mismatch = 0, geos_inconsistent = 0;
  for (int i = 0; i < kCasesPerFamily && failures < 3; ++i) {
    const std::uint64_t seed = 1000003ull * (static_cast<std::uint64_t>(fam) + 1) + static_cast<std::uint64_t>(i);
    testing::Rng rng(seed);
    const auto fps = testing::generate_case(fam, rng);
    auto c = testing::run_and_compare(fps, 1, 1e-9, oracle);
    count_mismatch += !c.counts_match;
    geos_inconsistent += c.geos_self_inconsistent;
    if (!c.ok && oracle == testing::Oracle::AreaAndValid && c.cmp.invalid_ours == 0) {
      const int bad = sampling_disagreements(fps, c.plans, 4000, seed);
      c.ok = bad == 0;
      if (!c.ok) c.message += "\nsampling oracle: " + std::to_string(bad) + " of 4000 points disagree";
    }
    if (!c.ok) {
      ++failures;
      ADD_FAILURE() << testing::family_name(fam) << " seed " << seed << ": " << c.message;
    }
  }
  RecordProperty("count_mismatches", count_mismatch);
  std::cout << "[ " << testing::family_name(fam) << " ] " << kCasesPerFamily << " cases, polygon/hole count differs from GEOS in "
            << count_mismatch << ", GEOS not a fixed point of its own union in " << geos_inconsistent << "\n";
}

INSTANTIATE_TEST_SUITE_P(Families, UnionProperty, ::testing::ValuesIn(testing::kAllFamilies),
                         [](const ::testing::TestParamInfo<Family>& info) {
                           return std::string(testing::family_name(info.param));
                         });

}  // namespace
}  // namespace groundplan

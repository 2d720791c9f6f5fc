// SPDX-License-Identifier: MIT
// Property tests of the union engine against GEOS UnaryUnion (issue 3): seeded random cases per
// degenerate family; every case must match (symmetric difference <= 1e-9 of the area, same
// numbers of polygons and holes, all valid, no overlaps). A failure prints the seed and the WKT:
// make it a named case in tests/unit/core/union_regression_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "robust/predicates.h"

#include "near_touch.h"
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
// points, which does not depend on GEOS. Counts there are reported only. In every family, when
// counts, areas and validity agree but GEOS's SymDifference does not (it can fail on near-coincident
// rounded vertices: UnionRegression.GeosSymDifferenceImplausibleSeed6000910), point sampling
// decides; the summary line counts how often. Near-touching output vertices (two distinct vertices
// within 8 ulps, or a vertex that close to an edge it is not on) fail every family (issue 20). Counts (and
// areas) that differ from GEOS's exact union pass the strict oracle only where the plans differ from it by
// material narrower than the snap pitch alone (features narrower than the pitch collapse:
// GeosComparison::below_pitch); the summary line counts those too.
class UnionProperty : public ::testing::TestWithParam<Family> {};

using testing::sampling_disagreements;

constexpr int kCasesPerFamily = 1000;

TEST_P(UnionProperty, MatchesGeos) {
  const Family fam = GetParam();
  const auto oracle = fam == Family::NearCollinear ? testing::Oracle::AreaAndValid : testing::Oracle::Strict;
  int failures = 0, count_mismatch = 0, collapsed = 0, geos_inconsistent = 0, symdiff_fallback = 0, near_touching = 0,
      near_touching_computed = 0;
  // dense rings (thousands of vertices a case) take 200 cases: 1000 were ~2 minutes of a Release build
  const int cases = fam == Family::DenseRings ? 200 : kCasesPerFamily;
  int ran = 0;
  for (int i = 0; i < cases && failures < 3; ++i, ++ran) {
    const std::uint64_t seed = 1000003ull * (static_cast<std::uint64_t>(fam) + 1) + static_cast<std::uint64_t>(i);
    testing::Rng rng(seed);
    const auto fps = testing::generate_case(fam, rng);
    auto c = testing::run_and_compare(fps, 1, 1e-9, oracle);
    count_mismatch += !c.counts_match;
    collapsed += c.collapsed_below_pitch;
    geos_inconsistent += c.geos_self_inconsistent;
    symdiff_fallback += c.geos_symdiff_implausible;
    if (!c.ok && oracle == testing::Oracle::AreaAndValid && c.cmp.invalid_ours == 0) {
      const int bad = sampling_disagreements(fps, c.plans, 4000, seed);
      c.ok = bad == 0;
      if (!c.ok) c.message += "\nsampling oracle: " + std::to_string(bad) + " of 4000 points disagree";
    }
    // Near-touch artefacts (tests/support/near_touch.h, issue 20): a failure in every family.
    const testing::NearTouch nt = testing::near_touch(c.plans, 8, &fps);
    if (nt.pairs) {
      ++near_touching;
      near_touching_computed += nt.computed > 0;
      c.ok = false;
      c.message = "near-touching output: " + nt.first + "\n" + c.message;
    }
    if (!c.ok) {
      ++failures;
      ADD_FAILURE() << testing::family_name(fam) << " seed " << seed << ": " << c.message;
    }
  }
  RecordProperty("count_mismatches", count_mismatch);
  std::cout << "[ " << testing::family_name(fam) << " ] " << ran << " cases, polygon/hole count differs from GEOS in "
            << count_mismatch << " (" << collapsed << " of them only by features narrower than the snap pitch), GEOS not a fixed point of its own union in " << geos_inconsistent
            << ", GEOS symmetric difference implausible (decided by sampling) in " << symdiff_fallback
            << ", near-touching output vertices in " << near_touching << " (at a point the union computed: "
            << near_touching_computed << ")\n";
}

INSTANTIATE_TEST_SUITE_P(Families, UnionProperty, ::testing::ValuesIn(testing::kAllFamilies),
                         [](const ::testing::TestParamInfo<Family>& info) {
                           return std::string(testing::family_name(info.param));
                         });

}  // namespace
}  // namespace groundplan

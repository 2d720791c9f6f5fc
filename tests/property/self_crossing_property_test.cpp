// SPDX-License-Identifier: MIT
// Issue 20: self-crossing rings (self_crossing_generator.h: bow-ties, figure-eights, retraced edges,
// spikes, rings through their own vertex, pentagrams; sevenths and elevenths) next to ordinary quads,
// 1000 seeded cases and a city of 3000 footprints at UTM coordinates.
//
// Held now, asserted: no exception; no problem but NO_AREA; every plan valid (GEOS isValid); no two
// plans overlapping (3 in 1000 cases did before robust::crossing_point rounded each crossing once); the
// plans cover exactly the even-odd region of the input (exact point membership at random points,
// an oracle independent of GEOS).
// Open (tests/corpus/fuzz-regressions/union/README.md), counted and printed, asserted only by the
// DISABLED_ tests (run them with --gtest_also_run_disabled_tests). Branch snap-round2: 965 of 1000
// cases strict-equal; 32 near-touch (valid output that near-touches is not snap-rounded:
// snap_round.h kSnapNearTouch), 11 other polygon/hole counts; with near-touch snapped too (the
// constant on) 990/1000, 1 near-touch, but large_offsets cases then differ from GEOS in counts.
// Branch robust20 (touch_cycle: a hole touching its shell twice is snap-rounded): 970 strict-equal,
// 27 near-touch, 12 other counts; constant on: 990, 1 near-touch, 12 other counts. Branch robust20c
// (kSnapComputedNearTouch: a valid group near-touching at a computed point is snapped too, unless that
// changes its ring counts): 986 strict-equal, 12 other counts, 8 near-touch (7 at a computed point).
// Branch robust20d (nesting_flips: a ring turned over by rounding is snap-rounded): the same 986; the 14 open
// seeds (printed one a line by the DISABLED_ test), read one by one against GEOS's WKT:
//  - 20000025: a hole ring that crosses itself as a pentagram and sticks out of its shell: by parity its inner
//    pentagon stays covered, GEOS MakeValid leaves it out (area 4.8% off); the even-odd sampling agrees with us.
//  - 20000279, 20000440, 20000679, 20000704: GEOS keeps a feature narrower than the snap pitch (a hole or a sliver
//    plan whose vertices are an ulp apart, a gap of an ulp between pieces) that snap rounding collapses, as
//    designed (docs/union_engine.md, "What collapses"); valid, same area.
//  - 20000837: f0's corner (2/7, 4/7 as doubles) lies exactly on f1's edge (checked with rationals): we give two
//    plans sharing that vertex, GEOS moves it an ulp and gives one plan with a hole.
//  - near-touch, 8: 20000261 between input vertices and edges only (GEOS's output has it too); 7 at a computed
//    point, kept as they are because snapping their group would change its ring counts (the guard of
//    kSnapComputedNearTouch). Snapping would give GEOS's counts in 20000668, 20000840, 20000992 and not in
//    20000021, 20000223, 20000634, 20000793 (in 20000021 a dart-shaped sliver plan narrower than the pitch, which
//    GEOS keeps, collapses); a rule telling the two apart without GEOS was not found.
// So no engine defect is left among them that this test can show: they are sub-pitch decisions where the
// strict criterion takes GEOS's rounding as the truth. The tests stay DISABLED_ (never loosened).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>

#include "near_touch.h"
#include "self_crossing_generator.h"
#include "union_test_util.h"

namespace groundplan {
namespace {

struct Tally {
  int cases = 0, strict_ok = 0, counts_differ = 0, overlapping = 0, near_touch = 0, near_touch_computed = 0;
  std::vector<std::string> hard;  // failures of what is asserted now
  std::string first_open;         // first failure of the strict criterion
  std::vector<std::string> open;  // every failure of the strict criterion, one line each
  void print(const char* what) const {
    std::cout << "[ " << what << " ] " << cases << " cases: " << strict_ok
              << " equal to GEOS MakeValid + UnaryUnion by DESIGN.md's criterion; open: " << overlapping
              << " with overlapping plans, " << counts_differ << " with other polygon/hole counts, " << near_touch
              << " with near-touching vertices (" << near_touch_computed << " at a point the union computed)\n";
  }
};

void check(const std::vector<Footprint>& fps, std::uint64_t seed, int samples, Tally& t) {
  const auto c = testing::run_and_compare(fps, 1);
  ++t.cases;
  auto hard = [&](const std::string& why) {
    std::ostringstream m;
    m << "seed " << seed << ": " << why << "\n" << c.message.substr(0, 3000);
    t.hard.push_back(m.str());
  };
  if (c.message.rfind("exception", 0) == 0) return hard(c.message);
  for (const Problem& p : c.problems)
    if (p.code != "NO_AREA") return hard("problem " + p.code + ": " + p.reason);
  if (c.cmp.invalid_ours) return hard("invalid plan: " + c.cmp.first_invalid_reason);
  if (c.cmp.overlapping_ours) return hard("two plans overlap");
  const int bad = testing::sampling_disagreements(fps, c.plans, samples, seed);
  if (bad) return hard(std::to_string(bad) + " sample points disagree with the even-odd union");
  const testing::NearTouch nt = testing::near_touch(c.plans, 8, &fps);
  t.strict_ok += c.ok && nt.pairs == 0;
  t.counts_differ += !c.counts_match;
  t.overlapping += c.cmp.overlapping_ours > 0;
  t.near_touch += nt.pairs > 0;
  t.near_touch_computed += nt.computed > 0;
  if (!c.ok || nt.pairs)
    t.open.push_back("seed " + std::to_string(seed) + ": " + (nt.pairs ? "near-touch " + nt.first + "; " : "") +
                     c.cmp.summary());
  if ((!c.ok || nt.pairs) && t.first_open.empty()) {
    std::ostringstream m;
    m << "seed " << seed << ": " << (nt.pairs ? nt.first + "; " : "") << c.message.substr(0, 3000);
    t.first_open = m.str();
  }
}

Tally run_cases() {
  Tally t;
  for (std::uint64_t i = 0; i < 1000; ++i) {
    const std::uint64_t seed = 20000000ull + i;
    std::mt19937_64 rng(seed);
    check(testing::self_crossing_case(rng), seed, 2000, t);
  }
  return t;
}

Tally run_city() {
  Tally t;
  check(testing::self_crossing_city(3000, 20, 500000, 5400000), 20, 20000, t);
  return t;
}

TEST(SelfCrossingRings, ValidAndEvenOddRegion) {
  const Tally t = run_cases();
  t.print("self-crossing rings");
  EXPECT_EQ(t.cases, 1000);
  for (std::size_t i = 0; i < t.hard.size() && i < 3; ++i) ADD_FAILURE() << t.hard[i];
}

TEST(SelfCrossingCity, ValidAndEvenOddRegion) {
  const Tally t = run_city();
  t.print("self-crossing city, 3000 footprints");
  for (std::size_t i = 0; i < t.hard.size() && i < 3; ++i) ADD_FAILURE() << t.hard[i];
}

// Open regressions of issue 20 (see the header): fail today.
TEST(SelfCrossingRings, DISABLED_MatchesGeosMakeValidUnionWithoutNearTouch) {
  const Tally t = run_cases();
  t.print("self-crossing rings");
  EXPECT_EQ(t.strict_ok, t.cases) << t.first_open;
  for (const std::string& o : t.open) std::cout << "  open: " << o << "\n";
}

TEST(SelfCrossingCity, DISABLED_MatchesGeosMakeValidUnionWithoutNearTouch) {
  const Tally t = run_city();
  t.print("self-crossing city, 3000 footprints");
  EXPECT_EQ(t.strict_ok, t.cases) << t.first_open;
}

}  // namespace
}  // namespace groundplan

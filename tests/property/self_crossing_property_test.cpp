// SPDX-License-Identifier: MIT
// Issue 20: self-crossing rings (self_crossing_generator.h: bow-ties, figure-eights, retraced edges,
// spikes, rings through their own vertex, pentagrams; sevenths and elevenths) next to ordinary quads,
// 1000 seeded cases and a city of 3000 footprints at UTM coordinates.
//
// Asserted, every case: no exception; no problem but NO_AREA; every plan valid (GEOS isValid); no two plans
// overlapping; the plans cover exactly the even-odd region of the input (exact point membership at random
// points, an oracle independent of GEOS); no near-touching output vertices (tests/support/near_touch.h).
// Asserted, every case and the city: DESIGN.md's criterion against GEOS MakeValid + UnaryUnion, where
// counts and area may differ only by material narrower than the snap pitch (GeosComparison::below_pitch:
// issue 20's "features narrower than δ collapse"), with no near-touch.
//
// The reference is GEOS MakeValid + UnaryUnion of the same footprints on their exact lattice (77 units a
// metre, integers: self_crossing_generator.h), brought back to metres. On the input in metres, sevenths
// and elevenths are rounded, and three lattice lines through one lattice point (a pentagram hole's tip
// edge, its long edge and the shell's side) meet a few ulps apart. GEOS's floating-point noding then
// decides the point inconsistently: on seed 20000025 (a pentagram hole sticking out of its shell)
// MakeValid's linework loop leaves the last cycle of cut edges open by one ulp (y 1.7142857142857142 vs
// ...44), builds no area from it and returns 70.52 m² where its own result on the lattice is 71.97 m², the
// even-odd area (which sampling confirms, and which exact linework gives: every cut edge is peeled once,
// so the symmetric differences add up to the even-odd rule). The seeds where GEOS's result in metres and
// on the lattice differ are printed; where ours differs from GEOS in metres, GEOS in metres must differ
// from GEOS on the lattice (asserted: the difference is GEOS's rounding, not ours).
// History: 965/1000 (snap-round2), 986 (robust20c/d: computed near-touch snapped unless counts changed), 999
// (every near-touching group snapped; differences below the pitch accepted, measured piece by piece), 1000
// and the city (the lattice reference).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>

#include "near_touch.h"
#include "self_crossing_generator.h"
#include "union_test_util.h"

namespace groundplan {
namespace {

/// GEOS MakeValid + UnaryUnion of the lattice copy, in metres.
std::vector<GroundPlan> lattice_reference(const std::vector<Footprint>& lattice) {
  std::vector<GroundPlan> ref = gis::geos_union(lattice);
  auto to_metres = [](Ring& r) {
    for (Point2& v : r) v = {v.x / testing::kCommonDen, v.y / testing::kCommonDen};
  };
  for (GroundPlan& g : ref) {
    to_metres(g.polygon.outer);
    for (Ring& h : g.polygon.holes) to_metres(h);
  }
  return ref;
}

struct Tally {
  int cases = 0, strict_ok = 0, counts_differ = 0, overlapping = 0, near_touch = 0, near_touch_computed = 0;
  std::vector<std::uint64_t> geos_in_metres_differs;  // GEOS on the input in metres is not GEOS on the lattice
  std::size_t problems = 0;       // NO_AREA problems (every other problem fails the case)
  int counts_not_below_pitch = 0;  // counts differ from GEOS by more than features narrower than the pitch
  std::vector<std::string> hard;  // failures of what is asserted now
  std::string first_open;         // first failure of the strict criterion
  std::vector<std::string> open;  // every failure of the strict criterion, one line each
  void print(const char* what) const {
    std::cout << "[ " << what << " ] " << cases << " cases: " << strict_ok
              << " equal to GEOS MakeValid + UnaryUnion by DESIGN.md's criterion; open: " << overlapping
              << " with overlapping plans, " << counts_differ << " with other polygon/hole counts (" << counts_not_below_pitch
              << " of them by more than features narrower than the snap pitch), " << near_touch
              << " with near-touching vertices (" << near_touch_computed << " at a point the union computed)\n";
  }
};

void check(const std::vector<Footprint>& fps, const std::vector<Footprint>& lattice, std::uint64_t seed, int samples,
           Tally& t) {
  const std::vector<GroundPlan> ref = lattice_reference(lattice);
  const auto c = testing::run_and_compare(fps, 1, 1e-9, testing::Oracle::Strict, &ref);
  ++t.cases;
  t.problems += c.problems.size();
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
  t.counts_not_below_pitch += !(c.cmp.counts_exact() || c.cmp.below_pitch());
  t.overlapping += c.cmp.overlapping_ours > 0;
  t.near_touch += nt.pairs > 0;
  t.near_touch_computed += nt.computed > 0;
  if (nt.pairs) hard("near-touching output: " + nt.first);
  const std::vector<GroundPlan> in_metres = gis::geos_union(fps);
  if (!testing::compare_union(fps, c.plans, c.problems, 1e-9, testing::Oracle::Strict, &in_metres).ok) {
    // Ours differs from GEOS on the input in metres: then GEOS there must differ from GEOS on the lattice.
    const gis::GeosComparison g = gis::compare_with_geos(fps, ref, &in_metres);
    if (g.matches())
      hard("ours differs from GEOS on the input in metres, which GEOS on the lattice matches: " + g.summary());
    t.geos_in_metres_differs.push_back(seed);
  }
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
    std::vector<Footprint> lattice;
    const std::vector<Footprint> fps = testing::self_crossing_case(rng, 0, 0, &lattice);
    check(fps, lattice, seed, 2000, t);
  }
  return t;
}

Tally run_city() {
  Tally t;
  std::vector<Footprint> lattice;
  const std::vector<Footprint> city = testing::self_crossing_city(3000, 20, 500000, 5400000, &lattice);
  check(city, lattice, 20, 20000, t);
  return t;
}

// Every case: what check() asserts (hard), and DESIGN.md's criterion against the lattice reference.
TEST(SelfCrossingRings, ValidEvenOddAndEqualToGeosMakeValidUnion) {
  const Tally t = run_cases();
  t.print("self-crossing rings");
  EXPECT_EQ(t.cases, 1000);
  for (std::size_t i = 0; i < t.hard.size() && i < 3; ++i) ADD_FAILURE() << t.hard[i];
  EXPECT_EQ(t.strict_ok, t.cases) << t.first_open;
  for (const std::string& o : t.open) std::cout << "  open: " << o << "\n";
  std::cout << "  GEOS on the input in metres differs from GEOS on the lattice (and from ours) on "
            << t.geos_in_metres_differs.size() << " seeds:";
  for (std::uint64_t s : t.geos_in_metres_differs) std::cout << " " << s;
  std::cout << "\n";
}

TEST(SelfCrossingCity, ValidEvenOddAndEqualToGeosMakeValidUnion) {
  const Tally t = run_city();
  t.print("self-crossing city, 3000 footprints");
  EXPECT_EQ(t.cases, 1);
  EXPECT_EQ(t.problems, 0u) << "the city's footprints all have area";
  for (std::size_t i = 0; i < t.hard.size() && i < 3; ++i) ADD_FAILURE() << t.hard[i];
  EXPECT_EQ(t.strict_ok, t.cases) << t.first_open;
  std::cout << "  GEOS on the city in metres differs from GEOS on the lattice: "
            << (t.geos_in_metres_differs.empty() ? "no" : "yes") << "\n";
}

}  // namespace
}  // namespace groundplan

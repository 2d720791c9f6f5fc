// SPDX-License-Identifier: MIT
// The shared near-touch check of the tests (tests/support/near_touch.h, issue 20) on hand-made plans.
#include <gtest/gtest.h>

#include <cmath>

#include "near_touch.h"

namespace groundplan {
namespace {

GroundPlan plan(Ring outer) {
  GroundPlan g;
  g.polygon.outer = std::move(outer);
  return g;
}

TEST(NearTouchCheck, ExactContactIsNoArtefact) {
  // two squares sharing a vertex, a triangle whose vertex lies exactly on the first square's edge
  const std::vector<GroundPlan> plans{plan({{0, 0}, {1, 0}, {1, 1}, {0, 1}}), plan({{1, 1}, {2, 1}, {2, 2}, {1, 2}}),
                                      plan({{-1, 0.5}, {0, 0.25}, {-1, 0}})};
  EXPECT_EQ(testing::near_touch(plans).pairs, 0u);
}

TEST(NearTouchCheck, VerticesAFewUlpsApart) {
  const double x = std::nextafter(std::nextafter(1.0, 2.0), 2.0);  // 2 ulps right of 1
  const std::vector<GroundPlan> plans{plan({{0, 0}, {1, 0}, {1, 1}, {0, 1}}), plan({{x, 1}, {2, 1}, {2, 2}, {1.5, 2}})};
  const auto nt = testing::near_touch(plans);
  EXPECT_EQ(nt.pairs, 1u);
  EXPECT_NE(nt.first.find("distinct but within"), std::string::npos) << nt.first;
  // 1e-9 apart at 5e5 is far more than a few ulps (1.2e-10): no artefact
  const std::vector<GroundPlan> far{plan({{5e5, 0}, {5e5 + 1, 0}, {5e5 + 1, 1}}),
                                    plan({{5e5 + 1 + 1e-9, 0}, {5e5 + 2, 0}, {5e5 + 2, 1}})};
  EXPECT_EQ(testing::near_touch(far).pairs, 0u);
}

TEST(NearTouchCheck, VertexWithinRoundingOfAnotherEdge) {
  const double y = std::nextafter(0.5, 1.0);  // one ulp off the edge x = 0, inside the square's edge range
  const std::vector<GroundPlan> plans{plan({{0, 0}, {1, 0}, {1, 1}, {0, 1}}),
                                      plan({{-1, 0.25}, {-1e-17, y}, {-1, 0.75}})};
  const auto nt = testing::near_touch(plans);
  EXPECT_EQ(nt.pairs, 1u);
  EXPECT_NE(nt.first.find("but not on it"), std::string::npos) << nt.first;
}

TEST(NearTouchCheck, TellsPairsTheUnionComputedFromPairsOfInputVertices) {
  // A triangle's vertex one ulp off the square's edge x = 0: as input, both plans are footprints, so the
  // pair is the input's own (an inexact rotation does this to a T-junction), not an artefact of the union.
  const double y = std::nextafter(0.5, 1.0);
  const Ring square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Ring triangle{{-1, 0.25}, {-1e-17, y}, {-1, 0.75}};
  const std::vector<GroundPlan> plans{plan(square), plan(triangle)};
  const std::vector<Footprint> input{Footprint{{Polygon{square, {}}}, {}, {}, {}, 0, 0},
                                     Footprint{{Polygon{triangle, {}}}, {}, {}, {}, 0, 0}};
  const auto nt = testing::near_touch(plans, 8, &input);
  EXPECT_EQ(nt.pairs, 1u);
  EXPECT_EQ(nt.computed, 0u) << nt.first_computed;
  // The same plans when the triangle's tip was computed (no input vertex): an artefact.
  const std::vector<Footprint> other_tip{input[0], Footprint{{Polygon{{{-1, 0.25}, {-1, 0.5}, {-1, 0.75}}, {}}}, {}, {}, {}, 0, 0}};
  const auto nt2 = testing::near_touch(plans, 8, &other_tip);
  EXPECT_EQ(nt2.pairs, 1u);
  EXPECT_EQ(nt2.computed, 1u);
  EXPECT_NE(nt2.first_computed.find("but not on it"), std::string::npos) << nt2.first_computed;
  // ... or an end of the edge it nearly touches was computed.
  const std::vector<Footprint> other_edge{Footprint{{Polygon{{{0, 0}, {1, 0}, {1, 1}, {0, 2}}, {}}}, {}, {}, {}, 0, 0},
                                          input[1]};
  EXPECT_EQ(testing::near_touch(plans, 8, &other_edge).computed, 1u);
  // Two vertices a few ulps apart, one of them computed.
  const double x = std::nextafter(std::nextafter(1.0, 2.0), 2.0);
  const std::vector<GroundPlan> vv{plan(square), plan({{x, 1}, {2, 1}, {2, 2}, {1.5, 2}})};
  const std::vector<Footprint> vv_input{input[0], Footprint{{Polygon{{{x, 0.5}, {2, 1}, {2, 2}, {1.5, 2}}, {}}}, {}, {}, {}, 0, 0}};
  const auto nt3 = testing::near_touch(vv, 8, &vv_input);
  EXPECT_EQ(nt3.pairs, 1u);
  EXPECT_EQ(nt3.computed, 1u);
  EXPECT_NE(nt3.first_computed.find("distinct but within"), std::string::npos) << nt3.first_computed;
  // Without the input nothing is called computed (the count of all pairs is what the callers had).
  EXPECT_EQ(testing::near_touch(vv).computed, 0u);
}

}  // namespace
}  // namespace groundplan

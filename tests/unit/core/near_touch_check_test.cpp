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

}  // namespace
}  // namespace groundplan

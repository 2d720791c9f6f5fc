// SPDX-License-Identifier: MIT
// The union's PlanFeed (ground_plans.h; issue 14: the CLI writes the plans while later blocks are still united):
// begun once with the number of blocks, told every block's plans once, their concatenation in block order is the
// result, and the end comes last, also when the run is cancelled; a level of detail never begins it.
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/ground_plans.h>
#include <groundplan/level_of_detail.h>

#include <mutex>
#include <string>
#include <vector>

#include "union_generators.h"

namespace groundplan {
namespace {

struct RecordingFeed final : PlanFeed {
  std::mutex m;
  std::vector<std::string> events;             // "begin", "end true" / "end false" (blocks are counted apart)
  std::size_t blocks = 0, after_end = 0;
  std::vector<int> told;                       // per block
  std::vector<std::vector<GroundPlan>> plans;  // per block
  bool ended = false;

  void begin(std::size_t n) override {
    std::lock_guard<std::mutex> l(m);
    events.push_back("begin");
    blocks = n;
    told.assign(n, 0);
    plans.assign(n, {});
  }
  void block_done(std::size_t b, const std::vector<GroundPlan>& p) override {
    std::lock_guard<std::mutex> l(m);
    after_end += ended;
    ASSERT_LT(b, told.size());
    ++told[b];
    plans[b] = p;
  }
  void end(bool complete) override {
    std::lock_guard<std::mutex> l(m);
    events.push_back(complete ? "end true" : "end false");
    ended = true;
  }
};

/// A synthetic city and, beyond it and before it, two terraces of 100 houses sharing walls: large blocks, which
/// the union takes first (so the order the blocks are united in is not block order).
std::vector<Footprint> city_with_terraces() {
  std::vector<Footprint> fps = testing::synthetic_city(3000, 11);
  for (double y0 : {-1000.0, 6e6}) {
    for (int i = 0; i < 100; ++i) {
      const double x = 500000 + 8.0 * i;
      Footprint f;
      f.source_id = "terrace" + std::to_string(i);
      f.polygons.push_back(Polygon{{{x, y0}, {x + 8, y0}, {x + 8, y0 + 10}, {x, y0 + 10}}, {}});
      fps.push_back(f);
    }
  }
  return fps;
}

TEST(PlanFeed, ToldEveryBlockOnceAndTheirPlansInBlockOrderAreTheResult) {
  const auto city = city_with_terraces();
  for (int threads : {1, 4}) {
    RecordingFeed feed;
    UnionStats stats;
    UnionParams p;
    p.threads = threads;
    p.stats = &stats;
    p.feed = &feed;
    std::vector<Problem> problems;
    const std::vector<GroundPlan> plans = build_ground_plans(city, p, problems);
    EXPECT_EQ(feed.events, (std::vector<std::string>{"begin", "end true"})) << threads;
    EXPECT_EQ(feed.blocks, stats.blocks);
    EXPECT_GT(feed.blocks, 100u);
    EXPECT_EQ(feed.after_end, 0u);
    std::vector<GroundPlan> joined;
    for (std::size_t b = 0; b < feed.blocks; ++b) {
      EXPECT_EQ(feed.told[b], 1) << "block " << b;
      joined.insert(joined.end(), feed.plans[b].begin(), feed.plans[b].end());
    }
    ASSERT_EQ(joined.size(), plans.size()) << threads;
    for (std::size_t i = 0; i < plans.size(); ++i) {
      EXPECT_EQ(joined[i].polygon.outer, plans[i].polygon.outer) << i;
      EXPECT_EQ(joined[i].polygon.holes, plans[i].polygon.holes) << i;
      EXPECT_EQ(joined[i].members, plans[i].members) << i;
      EXPECT_EQ(joined[i].area_m2, plans[i].area_m2) << i;
    }
  }
}

TEST(PlanFeed, ToldTheEndWhenTheUnionIsCancelled) {
  const auto city = testing::synthetic_city(3000, 12);
  for (int threads : {1, 4}) {
    RecordingFeed feed;
    UnionParams p;
    p.threads = threads;
    p.feed = &feed;
    std::vector<Problem> problems;
    Progress stop([](double, const char* what) { return std::string(what) != "union of blocks"; });
    EXPECT_THROW(build_ground_plans(city, p, problems, stop), Cancelled);
    EXPECT_EQ(feed.events, (std::vector<std::string>{"begin", "end false"})) << threads;
    EXPECT_EQ(feed.after_end, 0u);
  }
}

TEST(PlanFeed, NeverBegunWithALevelOfDetail) {
  const auto city = testing::synthetic_city(500, 13);
  RecordingFeed feed;
  UnionParams p;
  p.feed = &feed;
  LodParams lod;
  lod.snap_m = 0.01;  // the steps after the union change its plans: no feed may see them before
  std::vector<Problem> problems;
  EXPECT_FALSE(build_ground_plans(city, p, lod, problems).empty());
  EXPECT_TRUE(feed.events.empty());
}

}  // namespace
}  // namespace groundplan

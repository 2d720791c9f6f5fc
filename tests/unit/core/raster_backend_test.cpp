// SPDX-License-Identifier: MIT
// The CPU raster backend (paper §5 blocks, §3 Update seeds) behind the RasterBackend seam.
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include <algorithm>
#include <cmath>

#include "union_test_util.h"

namespace groundplan {
namespace {

std::vector<Block> blocks_of(const std::vector<Footprint>& fps, double res) {
  auto set = make_footprint_set(fps);
  auto grid = make_pixel_grid(set, res);
  return make_raster_backend(Device::Cpu)->find_blocks(set, grid, {});
}

TEST(RasterBackend, FootprintsTouchingAtOnePointShareABlockAtAnyResolution) {
  const auto fps = testing::footprints_from_wkt(
      {"POLYGON((0 0, 1 0, 1 1, 0 1, 0 0))", "POLYGON((1 1, 2 1, 2 2, 1 2, 1 1))", "POLYGON((5 5, 6 5, 6 6, 5 6, 5 5))"});
  for (double res : {0.0, 0.1, 0.3, 0.7, 1.0, 1.0 / 3.0}) {
    const auto blocks = blocks_of(fps, res);
    ASSERT_EQ(blocks.size(), 2u) << res;
    auto big = std::max_element(blocks.begin(), blocks.end(),
                                [](const Block& a, const Block& b) { return a.footprints.size() < b.footprints.size(); });
    EXPECT_EQ(big->footprints, (std::vector<std::uint32_t>{0, 1})) << res;
  }
}

TEST(RasterBackend, NestedFootprintIsInItsHostsBlock) {
  const auto fps = testing::footprints_from_wkt({"POLYGON((0 0, 100 0, 100 100, 0 100, 0 0))", "POLYGON((40 40, 41 40, 41 41, 40 41, 40 40))"});
  EXPECT_EQ(blocks_of(fps, 0.5).size(), 1u);
}

TEST(RasterBackend, FootprintsWithoutFiniteVerticesAreLeftOut) {
  std::vector<Footprint> fps(2);
  fps[0].polygons.push_back(Polygon{{{0, 0}, {1, 0}, {0, 1}}, {}});
  fps[1].polygons.push_back(Polygon{{{std::nan(""), 0}, {HUGE_VAL, 1}, {0, std::nan("")}}, {}});
  const auto set = make_footprint_set(fps);
  EXPECT_EQ(set.indices, std::vector<std::uint32_t>{0});
}

TEST(RasterBackend, AutomaticResolutionKeepsThePixelBudget) {
  // one tiny footprint must not force millimetre pixels on a kilometre of footprints
  std::vector<std::string> w{"POLYGON((0 0, 0.001 0, 0.001 0.001, 0 0.001, 0 0))"};
  for (int i = 0; i < 100; ++i) {
    const double x = 10.0 * i;
    w.push_back("POLYGON((" + std::to_string(x) + " 0, " + std::to_string(x + 8) + " 0, " + std::to_string(x + 8) + " 8, " +
                std::to_string(x) + " 8, " + std::to_string(x) + " 0))");
  }
  const auto set = make_footprint_set(testing::footprints_from_wkt(w));
  const auto grid = make_pixel_grid(set, 0);
  EXPECT_GT(grid.resolution_m, 1.0);
  EXPECT_LT(static_cast<double>(grid.width) * static_cast<double>(grid.height), 1e6);
}

TEST(RasterBackend, NewSeedsFromPixelsFindAHoleAndAMissingOuterRing) {
  const auto fps = testing::footprints_from_wkt(
      {"POLYGON((0 0, 30 0, 30 30, 0 30, 0 0), (10 10, 10 20, 20 20, 20 10, 10 10))", "POLYGON((40 0, 50 0, 50 10, 40 10, 40 0))"});
  const auto set = make_footprint_set(fps);
  const auto grid = make_pixel_grid(set, 1.0);
  auto backend = make_raster_backend(Device::Cpu);
  Block block;
  block.footprints = {0, 1};
  // "so far": the outer ring of the first footprint only (no hole, no second building)
  GroundPlan so_far;
  so_far.polygon.outer = {{0, 0}, {30, 0}, {30, 30}, {0, 30}};
  const Seeds seeds = backend->find_new_seeds(set, block, {so_far}, grid);
  bool in_hole = false, in_second = false;
  for (const auto& p : seeds.pixels) {
    const double x = grid.origin_x + (static_cast<double>(p.col) + 0.5) * grid.resolution_m;
    const double y = grid.origin_y + (static_cast<double>(p.row) + 0.5) * grid.resolution_m;
    in_hole |= x > 10 && x < 20 && y > 10 && y < 20;
    in_second |= x > 40 && x < 50 && y > 0 && y < 10;
  }
  EXPECT_TRUE(in_hole);
  EXPECT_TRUE(in_second);
}

TEST(RasterBackend, CudaIsRefusedUntilIssue4AutoIsCpu) {
  EXPECT_THROW(make_raster_backend(Device::Cuda), GpuError);
  EXPECT_STREQ(make_raster_backend(Device::Auto)->name(), "cpu");
}

}  // namespace
}  // namespace groundplan

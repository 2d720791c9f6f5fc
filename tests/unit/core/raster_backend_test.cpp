// SPDX-License-Identifier: MIT
// The CPU raster backend (paper §5 blocks, §3 Update seeds) behind the RasterBackend seam.
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "blocks/cpu_raster_backend.h"
#include "blocks/raster_common.h"
#include "union_generators.h"
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

TEST(RasterBackend, CpuIsCpuAutoIsCudaOnlyWithADeviceCudaIsCudaOrAGpuError) {
  EXPECT_STREQ(make_raster_backend(Device::Cpu)->name(), "cpu");
  std::unique_ptr<RasterBackend> cuda;
  try {
    cuda = make_raster_backend(Device::Cuda);
  } catch (const GpuError& e) {
    EXPECT_NE(std::string(e.what()).find("--device cpu"), std::string::npos) << e.what();
  }
  if (cuda) {
    EXPECT_STREQ(cuda->name(), "cuda");
  }
  // Auto is the CPU, with a device or without (tests/gpu checks with one): the GPU never paid for its start.
  EXPECT_STREQ(make_raster_backend(Device::Auto)->name(), "cpu");
}

// City scale: rows are processed in bands of bounded keys; components crossing band edges are
// merged through the union-find on labels, so the blocks never depend on the band size.
TEST(RasterBackend, BandsOfAnySizeGiveTheSameBlocksAndSeeds) {
  const auto city = testing::synthetic_city(3000, 7);
  const auto set = make_footprint_set(city);
  for (double res : {0.0, 0.5, 3.0}) {
    const auto grid = make_pixel_grid(set, res);
    detail::CpuRasterBackend whole(std::uint64_t{1} << 40);
    const auto ref = whole.find_blocks(set, grid, {});
    for (std::uint64_t band : {1ull, 7ull, 500ull, 20000ull}) {
      detail::CpuRasterBackend banded(band);
      const auto got = banded.find_blocks(set, grid, {});
      ASSERT_EQ(got.size(), ref.size()) << res << " " << band;
      for (std::size_t i = 0; i < ref.size(); ++i) {
        EXPECT_EQ(got[i].footprints, ref[i].footprints) << res << " " << band << " block " << i;
        EXPECT_EQ(got[i].seed_col, ref[i].seed_col);
        EXPECT_EQ(got[i].seed_row, ref[i].seed_row);
      }
    }
  }
}

TEST(RasterBackend, BlocksAreOrderedByFirstFootprintAndSeededAtTheirTopRightPixel) {
  const auto set = make_footprint_set(testing::synthetic_city(2000, 3));
  const auto grid = make_pixel_grid(set, 0);
  const auto blocks = make_raster_backend(Device::Cpu)->find_blocks(set, grid, {});
  std::vector<int> seen(set.indices.size(), 0);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    ASSERT_FALSE(blocks[b].footprints.empty());
    EXPECT_TRUE(std::is_sorted(blocks[b].footprints.begin(), blocks[b].footprints.end()));
    if (b) {
      EXPECT_LT(blocks[b - 1].footprints.front(), blocks[b].footprints.front());
    }
    std::int64_t col = -1, row = -1;
    for (auto f : blocks[b].footprints) {
      ++seen[f];
      const auto& box = set.boxes[f];  // synthetic_city footprints are all usable: index == position
      const std::int64_t c = detail::pixel_index(box.maxx, grid.origin_x, grid.resolution_m, grid.width);
      const std::int64_t r = detail::pixel_index(box.maxy, grid.origin_y, grid.resolution_m, grid.height);
      if (c > col || (c == col && r > row)) col = c, row = r;
    }
    EXPECT_EQ(blocks[b].seed_col, col);
    EXPECT_EQ(blocks[b].seed_row, row);
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int k) { return k == 1; }));
}

TEST(RasterBackend, RowBandsCoverEveryRowOnceWithinTheBudget) {
  detail::PixelRanges pr;
  auto add = [&](std::int64_t c0, std::int64_t c1, std::int64_t r0, std::int64_t r1) {
    pr.c0.push_back(c0), pr.c1.push_back(c1), pr.r0.push_back(r0), pr.r1.push_back(r1);
  };
  add(0, 9, 0, 4);      // 10 keys a row
  add(0, 99, 3, 3);     // one row of 100 keys (over a budget of 30)
  add(5, 5, 20, 40);    // after a gap of empty rows
  add(0, 2, 10, 12);
  for (std::uint64_t budget : {1ull, 30ull, 1000ull}) {
    const auto bands = detail::plan_row_bands(pr, budget);
    ASSERT_FALSE(bands.empty());
    EXPECT_EQ(bands.front().row0, 0);
    EXPECT_EQ(bands.back().row1, 40);
    for (std::size_t b = 0; b < bands.size(); ++b) {
      EXPECT_LE(bands[b].row0, bands[b].row1);
      if (b) {
        EXPECT_EQ(bands[b].row0, bands[b - 1].row1 + 1);
      }
      std::uint64_t keys = 0;
      int rows_with_keys = 0;
      for (std::int64_t r = bands[b].row0; r <= bands[b].row1; ++r) {
        std::uint64_t row_keys = 0;
        for (std::size_t i = 0; i < pr.c0.size(); ++i)
          if (pr.r0[i] <= r && r <= pr.r1[i]) row_keys += static_cast<std::uint64_t>(pr.c1[i] - pr.c0[i] + 1);
        keys += row_keys;
        rows_with_keys += row_keys > 0;
      }
      // over the budget only as a single row with keys (empty rows cost nothing)
      if (keys > budget) {
        EXPECT_EQ(rows_with_keys, 1) << budget << " band " << b;
      }
    }
  }
  EXPECT_EQ(detail::plan_row_bands(pr, 1000).size(), 1u);
}

}  // namespace
}  // namespace groundplan

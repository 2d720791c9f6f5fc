// SPDX-License-Identifier: MIT
// The CUDA raster backend gives the CPU backend's blocks and seeds bit for bit (issue 4) on every
// input here: synthetic cities of several sizes and resolutions, every degenerate property-test
// family, touching and nested cases, and small device bands (tiling). Labelled "gpu" in ctest;
// skipped (GTEST_SKIP) where the CUDA module (libgroundplan_cuda.so.0) is not built or no device answers,
// as in CI.
#include <gtest/gtest.h>

#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include <memory>
#include <string>
#include <vector>

#include "blocks/cpu_raster_backend.h"
#include "blocks/cuda_raster_backend.h"
#include "union_generators.h"

namespace groundplan {
namespace {

std::unique_ptr<RasterBackend> cuda_or_null(std::string* why) {
  try {
    return make_raster_backend(Device::Cuda);
  } catch (const GpuError& e) {
    *why = e.what();
    return nullptr;
  }
}

#define REQUIRE_CUDA(backend)                        \
  std::string why_;                                  \
  auto backend = cuda_or_null(&why_);                \
  if (!backend) GTEST_SKIP() << "no CUDA: " << why_;

Footprint square(double x0, double y0, double x1, double y1, std::vector<Ring> holes = {}) {
  Footprint f;
  f.polygons.push_back(Polygon{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, std::move(holes)});
  return f;
}

std::vector<GroundPlan> partial_plan(const std::vector<Footprint>& fps, const Block& b) {
  std::vector<GroundPlan> so_far(1);
  const auto& f = fps[b.footprints.front()];
  if (!f.polygons.empty()) so_far[0].polygon = f.polygons.front();
  return so_far;
}

/// Blocks and (for up to max_seed_blocks blocks) Update seeds of both backends must be equal.
void expect_same(RasterBackend& gpu, const std::vector<Footprint>& fps, double res, const std::string& what,
                 std::size_t max_seed_blocks = 200) {
  const auto set = make_footprint_set(fps);
  const auto grid = make_pixel_grid(set, res);
  detail::CpuRasterBackend cpu;
  const auto ref = cpu.find_blocks(set, grid, {});
  const auto got = gpu.find_blocks(set, grid, {});
  ASSERT_EQ(got.size(), ref.size()) << what;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    ASSERT_EQ(got[i].footprints, ref[i].footprints) << what << " block " << i;
    ASSERT_EQ(got[i].seed_col, ref[i].seed_col) << what << " block " << i;
    ASSERT_EQ(got[i].seed_row, ref[i].seed_row) << what << " block " << i;
  }
  for (std::size_t i = 0; i < ref.size() && i < max_seed_blocks; ++i) {
    for (const auto& so_far : {std::vector<GroundPlan>{}, partial_plan(fps, ref[i])}) {
      const Seeds a = cpu.find_new_seeds(set, ref[i], so_far, grid);
      const Seeds b = gpu.find_new_seeds(set, ref[i], so_far, grid);
      ASSERT_EQ(a.pixels.size(), b.pixels.size()) << what << " seeds of block " << i;
      for (std::size_t k = 0; k < a.pixels.size(); ++k) {
        ASSERT_EQ(a.pixels[k].col, b.pixels[k].col) << what << " seeds of block " << i;
        ASSERT_EQ(a.pixels[k].row, b.pixels[k].row) << what << " seeds of block " << i;
      }
    }
  }
}

// Auto takes the GPU only when the work pays for starting CUDA (kCudaAutoMinFootprints); an
// explicit Cuda always does. The pipeline's default is Auto, so a small city on a GPU host must not
// wait ~0.3 s for a context it does not need.
TEST(CudaRasterBackend, AutoTakesTheGpuOnlyForLargeInputs) {
  REQUIRE_CUDA(gpu);
  EXPECT_STREQ(gpu->name(), "cuda");
  EXPECT_STREQ(make_raster_backend(Device::Auto, 1000)->name(), "cpu");
  EXPECT_STREQ(make_raster_backend(Device::Auto, kCudaAutoMinFootprints - 1)->name(), "cpu");
  EXPECT_STREQ(make_raster_backend(Device::Auto, kCudaAutoMinFootprints)->name(), "cuda");
  EXPECT_STREQ(make_raster_backend(Device::Cuda, 1000)->name(), "cuda");
}

TEST(CudaRasterBackend, SameAsCpuOnSyntheticCities) {
  REQUIRE_CUDA(gpu);
  for (std::size_t n : {1u, 10u, 600u, 6000u, 100000u})
    for (double res : {0.0, 0.25, 2.0, 50.0})
      expect_same(*gpu, testing::synthetic_city(n, n + 1), res, "city " + std::to_string(n) + " res " + std::to_string(res),
                  n <= 6000 ? 200 : 20);
}

TEST(CudaRasterBackend, SameAsCpuOnEveryDegenerateFamily) {
  REQUIRE_CUDA(gpu);
  for (testing::Family f : testing::kAllFamilies) {
    testing::Rng rng(42);
    for (int c = 0; c < 40; ++c) {
      const auto fps = testing::generate_case(f, rng);
      for (double res : {0.0, 0.1, 1.0 / 3.0, 1.0})
        expect_same(*gpu, fps, res, std::string(testing::family_name(f)) + " case " + std::to_string(c));
    }
  }
}

TEST(CudaRasterBackend, SameAsCpuOnTouchingAndNestedFootprints) {
  REQUIRE_CUDA(gpu);
  // corner contact, a separate one, a courtyard building, a footprint nested in it, an edge contact
  const std::vector<Footprint> fps{square(0, 0, 1, 1),    square(1, 1, 2, 2),
                                   square(5, 5, 6, 6),    square(0, 0, 100, 100, {{{10, 10}, {10, 20}, {20, 20}, {20, 10}}}),
                                   square(40, 40, 41, 41), square(2, 0, 3, 1)};
  for (double res : {0.0, 0.1, 0.3, 0.7, 1.0, 1.0 / 3.0, 7.0}) expect_same(*gpu, fps, res, "touching " + std::to_string(res));
  expect_same(*gpu, {}, 0.0, "empty");
}

TEST(CudaRasterBackend, DeviceBandsOfAnySizeGiveTheCpuBlocks) {
  REQUIRE_CUDA(any);
  for (std::uint64_t band : {1ull, 97ull, 5000ull}) {
    auto gpu = detail::make_cuda_raster_backend(band);
    expect_same(*gpu, testing::synthetic_city(3000, 11), 0.0, "band " + std::to_string(band), 10);
  }
}

}  // namespace
}  // namespace groundplan

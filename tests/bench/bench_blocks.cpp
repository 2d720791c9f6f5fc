// SPDX-License-Identifier: MIT
// Blocks (paper §5) and Update seeds (§3) benchmark and CPU/CUDA agreement check (issue 4). Needs
// only groundplan_core and tests/support/union_generators.cpp (no GDAL, GEOS or gtest), so that
// tests/gpu/standalone can build it on a GPU machine without the GIS stack.
//
//   bench_blocks --n 100000 [--device cpu|cuda|auto] [--runs 5] [--seed 1] [--band-keys K] [--check]
//                [--seed-blocks 1000]
// prints one line: device n footprints_set_s grid_s blocks_median_s blocks_min_s blocks n_keys_est
// seeds_per_block_ms peak_rss_mib; with --check also compares blocks and seeds with the CPU backend
// and exits 1 on any difference.
#include <groundplan/error.h>
#include <groundplan/raster_backend.h>


#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "blocks/cpu_raster_backend.h"
#include "bench_util.h"
#include "union_generators.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

using groundplan::bench::peak_rss_mib;

bool same_blocks(const std::vector<groundplan::Block>& a, const std::vector<groundplan::Block>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].footprints != b[i].footprints || a[i].seed_col != b[i].seed_col || a[i].seed_row != b[i].seed_row)
      return false;
  return true;
}

/// A "plan so far" for the Update check: the outer ring of the block's first footprint.
std::vector<groundplan::GroundPlan> partial_plan(const std::vector<groundplan::Footprint>& fps,
                                                 const groundplan::Block& b) {
  std::vector<groundplan::GroundPlan> so_far(1);
  const auto& f = fps[b.footprints.front()];
  if (!f.polygons.empty()) so_far[0].polygon.outer = f.polygons.front().outer;
  return so_far;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace groundplan;
  std::size_t n = 6000, runs = 5, seed_blocks = 1000;
  std::uint64_t seed = 1, band_keys = 0;
  std::string device = "cpu";
  bool check = false;
  for (int i = 1; i < argc; ++i) {
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--n")) n = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--runs")) runs = std::max<std::size_t>(1, std::strtoull(next(), nullptr, 10));
    else if (!std::strcmp(argv[i], "--seed")) seed = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--band-keys")) band_keys = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--seed-blocks")) seed_blocks = std::strtoull(next(), nullptr, 10);
    else if (!std::strcmp(argv[i], "--device")) device = next();
    else if (!std::strcmp(argv[i], "--check")) check = true;
    else {
      std::fprintf(stderr, "unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  const std::vector<Footprint> fps = testing::synthetic_city(n, seed);
  std::unique_ptr<RasterBackend> backend;
  try {
    if (device == "cpu" && band_keys) backend = std::make_unique<detail::CpuRasterBackend>(band_keys);
    else backend = make_raster_backend(device == "cuda" ? Device::Cuda : device == "auto" ? Device::Auto : Device::Cpu);
  } catch (const GpuError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 3;
  }
  auto t = Clock::now();
  const FootprintSet set = make_footprint_set(fps);
  const double set_s = since(t);
  t = Clock::now();
  const PixelGrid grid = make_pixel_grid(set, 0);
  const double grid_s = since(t);
  double marks = 0;  // the keys the raster makes (same count on every backend)
  for (const auto& b : set.boxes) {
    const auto span = [&](double lo, double hi, double o) {
      return std::floor((hi - o) / grid.resolution_m) - std::floor((lo - o) / grid.resolution_m) + 1;
    };
    marks += span(b.minx, b.maxx, grid.origin_x) * span(b.miny, b.maxy, grid.origin_y);
  }
  std::vector<double> times;
  std::vector<Block> blocks;
  for (std::size_t r = 0; r < runs; ++r) {
    t = Clock::now();
    blocks = backend->find_blocks(set, grid, {});
    times.push_back(since(t));
  }
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  // Update on the first seed_blocks blocks, each against the outer ring of its first footprint
  const std::size_t sb = std::min(seed_blocks, blocks.size());
  std::vector<Seeds> seeds(sb);
  t = Clock::now();
  for (std::size_t i = 0; i < sb; ++i) seeds[i] = backend->find_new_seeds(set, blocks[i], partial_plan(fps, blocks[i]), grid);
  const double seeds_ms = sb ? 1e3 * since(t) / static_cast<double>(sb) : 0;
  std::printf("%s n=%zu set_s=%.4f grid_s=%.4f blocks_median_s=%.4f blocks_min_s=%.4f blocks=%zu keys=%.0f "
              "res_m=%.3f grid=%lldx%lld seeds_per_block_ms=%.4f peak_rss_mib=%.1f\n",
              backend->name(), n, set_s, grid_s, sorted[sorted.size() / 2], sorted.front(), blocks.size(), marks,
              grid.resolution_m, static_cast<long long>(grid.width), static_cast<long long>(grid.height), seeds_ms,
              peak_rss_mib());
  if (check) {
    detail::CpuRasterBackend cpu;
    const auto ref = cpu.find_blocks(set, grid, {});
    if (!same_blocks(ref, blocks)) {
      std::printf("CHECK FAILED: %s blocks differ from the CPU's (%zu vs %zu blocks)\n", backend->name(),
                  blocks.size(), ref.size());
      return 1;
    }
    std::size_t seed_pixels = 0;
    for (std::size_t i = 0; i < sb; ++i) {
      const Seeds s = cpu.find_new_seeds(set, ref[i], partial_plan(fps, ref[i]), grid);
      bool same = s.pixels.size() == seeds[i].pixels.size();
      for (std::size_t k = 0; same && k < s.pixels.size(); ++k)
        same = s.pixels[k].col == seeds[i].pixels[k].col && s.pixels[k].row == seeds[i].pixels[k].row;
      if (!same) {
        std::printf("CHECK FAILED: %s seeds of block %zu differ from the CPU's\n", backend->name(), i);
        return 1;
      }
      seed_pixels += s.pixels.size();
    }
    std::printf("CHECK OK: %s = cpu on %zu blocks and the seeds of %zu blocks (%zu seed pixels)\n", backend->name(),
                blocks.size(), sb, seed_pixels);
  }
  return 0;
}

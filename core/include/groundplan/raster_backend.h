// SPDX-License-Identifier: MIT
#pragma once
// The raster half of the union (paper §5 blocks, §3 Update seeds) behind one interface, so that a
// CUDA backend (issue 4) can replace the CPU one (STYLE.md §6). Pixels and labels are integers:
// blocks and seeds are exact functions of the pixel grid, identical on every backend.
//
// Exactness never depends on the raster: a block may hold footprints that do not touch (they are
// split into separate ground plans by the union), and the union engine proves on its own, exactly,
// that it has found every ring (core/src/union/block_union.cpp). What the raster must guarantee is
// only that footprints whose closed regions meet share a block.
#include <groundplan/ground_plans.h>
#include <groundplan/progress.h>
#include <groundplan/types.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace groundplan {

/// Axis-parallel pixel grid in the working CRS. Pixel (col, row) covers
/// [origin_x + col*res, origin_x + (col+1)*res) x [origin_y + row*res, ...).
struct PixelGrid {
  double origin_x = 0, origin_y = 0;
  double resolution_m = 1;
  std::int64_t width = 0, height = 0;
};

/// Footprints prepared for rasterisation: the usable ones (with at least one finite vertex) and
/// their closed bounding boxes.
struct FootprintSet {
  struct Box {
    double minx, miny, maxx, maxy;
  };
  const std::vector<Footprint>* footprints = nullptr;
  std::vector<std::uint32_t> indices;  // indices into *footprints
  std::vector<Box> boxes;              // boxes[i] belongs to indices[i]
};

/// A set of footprints whose pixels are connected (paper §5), with its rightmost pixel as seed.
struct Block {
  std::vector<std::uint32_t> footprints;  // indices into the footprint vector, ascending
  std::int64_t seed_col = 0, seed_row = 0;
};

/// Seed pixels for further boundaries of a block (paper §3 Update): pixels covered by the block's
/// footprints but outside the plans found so far (another outer boundary), or inside them but
/// covered by no footprint (a hole).
struct Seeds {
  struct Pixel {
    std::int64_t col, row;
  };
  std::vector<Pixel> pixels;
};

struct RasterBackend {
  virtual ~RasterBackend() = default;
  virtual const char* name() const = 0;
  /// Paper §5: connected components of the footprints' pixels. Footprints whose closed regions
  /// meet are always in one block (conservative rasterisation).
  virtual std::vector<Block> find_blocks(const FootprintSet& fps, const PixelGrid& grid, const Progress& progress) = 0;
  /// Paper §3 Update, on the block's pixels.
  virtual Seeds find_new_seeds(const FootprintSet& fps, const Block& block, const std::vector<GroundPlan>& so_far,
                               const PixelGrid& grid) = 0;
};

/// Builds the set from footprints (drops those without a vertex, and those with a coordinate the exact
/// arithmetic refuses: robust/coordinate_range.h).
FootprintSet make_footprint_set(const std::vector<Footprint>& footprints);

/// The grid over the set. resolution_m > 0 is used as given (coarsened only if the grid would
/// exceed 2^31 pixels a side); 0 = automatic: the paper's rule (the smallest footprint's bounding
/// box covers at least 4 pixels), coarsened so that the footprints mark about 4 pixels each on
/// average: the raster only finds blocks, so a coarser one costs no exactness.
PixelGrid make_pixel_grid(const FootprintSet& fps, double resolution_m);

/// Cpu and Auto: the CPU backend. Cuda: the CUDA backend, or GpuError when it is not built in or no device
/// answers. Auto never takes the GPU: on every host measured the CPU found the blocks faster, CUDA's start
/// counted (0.06 s against 0.33 s for a 1.5 GB city on 16 cores, tests/bench/RESULTS.md). Every backend
/// gives the same blocks and seeds.
std::unique_ptr<RasterBackend> make_raster_backend(Device requested);

}  // namespace groundplan

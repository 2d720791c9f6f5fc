// SPDX-License-Identifier: MIT
#pragma once
// What the CPU and the CUDA raster backends share, so that they agree bit for bit (STYLE.md §5):
// the pixel index of a coordinate, the even-odd pixel-centre test of the Update seeds (on
// flattened rings, usable on the host and in a kernel), the row bands that bound the memory of a
// city (tiling), and the assembly of blocks from union-find roots. Plain C++: the host-device
// qualifiers below appear only when nvcc compiles a .cu that includes this file.
#include <groundplan/raster_backend.h>

#include <cmath>
#include <cstdint>
#include <vector>

#if defined(__CUDACC__)
#define GROUNDPLAN_HD __host__ __device__
#else
#define GROUNDPLAN_HD
#endif

namespace groundplan::detail {

/// Column (or row) of coordinate v: floor((v - origin) / res) clamped to [0, n). Subtraction,
/// division by a positive number and floor are monotone and correctly rounded in IEEE double on
/// both the host and the device (no FMA: -ffp-contract=off, --fmad=false), so the index is the
/// same on both, and two closed intervals that meet get index ranges that meet.
GROUNDPLAN_HD inline std::int64_t pixel_index(double v, double origin, double res, std::int64_t n) {
  const std::int64_t i = static_cast<std::int64_t>(::floor((v - origin) / res));
  return i < 0 ? 0 : (i > n - 1 ? n - 1 : i);
}

/// Polygons with holes as flat arrays: shape s has polygons [shape_first[s], shape_first[s+1]),
/// polygon p has rings [poly_first[p], poly_first[p+1]) (the first is the outer ring), ring r has
/// points [ring_first[r], ring_first[r+1]) in xs/ys.
struct FlatShapes {
  std::vector<std::uint32_t> shape_first{0}, poly_first{0}, ring_first{0};
  std::vector<double> xs, ys;
  void add_polygon(const Polygon& p);
  void add_footprint(const Footprint& f);
  void add_plan(const GroundPlan& g);
  std::uint32_t size() const { return static_cast<std::uint32_t>(shape_first.size() - 1); }
};

/// Even-odd test of the point (x, y) per polygon; true when inside any polygon of the shape. A
/// hint only (seeds), but the same arithmetic in the same order on the host and on the device.
GROUNDPLAN_HD inline bool inside_flat_shape(const std::uint32_t* shape_first, const std::uint32_t* poly_first,
                                            const std::uint32_t* ring_first, const double* xs, const double* ys,
                                            std::uint32_t s, double x, double y) {
  for (std::uint32_t p = shape_first[s]; p < shape_first[s + 1]; ++p) {
    bool odd = false;
    for (std::uint32_t r = poly_first[p]; r < poly_first[p + 1]; ++r) {
      const std::uint32_t b = ring_first[r], e = ring_first[r + 1];
      for (std::uint32_t i = b; i < e; ++i) {
        const std::uint32_t j = i + 1 < e ? i + 1 : b;
        const double ax = xs[i], ay = ys[i], bx = xs[j], by = ys[j];
        if ((ay > y) != (by > y) && x < ax + (y - ay) * (bx - ax) / (by - ay)) odd = !odd;
      }
    }
    if (odd) return true;
  }
  return false;
}

/// Inclusive pixel ranges of the set's bounding boxes on the grid.
struct PixelRanges {
  std::vector<std::int64_t> c0, c1, r0, r1;
};

/// Rows [row0, row1] processed together: the (pixel, label) keys of a band fit the budget, except
/// that a single row is never split. Components are merged across bands through one union-find on
/// labels, so the blocks do not depend on the bands.
struct RowBand {
  std::int64_t row0, row1;
};
std::vector<RowBand> plan_row_bands(const PixelRanges& pr, std::uint64_t key_budget);

/// Blocks from the union-find roots (root[i] = the smallest label of i's component): blocks in
/// order of their smallest label, footprints ascending, seed = the rightmost (then topmost)
/// pixel of the members' boxes (paper §5).
std::vector<Block> assemble_blocks(const FootprintSet& fps, const std::vector<std::uint32_t>& root,
                                   const std::int64_t* c1, const std::int64_t* r1);

/// The pixel-centre rectangle [c0, c1] x [r0, r1] that the Update seeds sample for a block, and
/// the block's footprints and the plans so far, flattened (shapes [0, n_footprints) are
/// footprints, the rest plans).
struct SeedProblem {
  std::int64_t c0 = 0, c1 = -1, r0 = 0, r1 = -1;
  std::uint32_t n_footprints = 0;
  FlatShapes shapes;
};
SeedProblem make_seed_problem(const FootprintSet& fps, const Block& block, const std::vector<GroundPlan>& so_far,
                              const PixelGrid& grid);

}  // namespace groundplan::detail

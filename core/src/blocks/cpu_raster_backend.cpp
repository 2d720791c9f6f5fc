// SPDX-License-Identifier: MIT
// Blocks from pixels (paper §5) on the CPU; the CUDA backend (gpu/src/cuda_raster_backend.cu)
// computes the same blocks with the same functions (blocks/raster_common.h). Each footprint marks the pixels of its closed bounding
// box. The marking is conservative without any widening: the pixel index floor((x - origin) / res)
// is a monotone function of x in floating point (subtraction, division by a positive number and
// floor are all monotone under rounding), and it is the same function for every footprint, so two
// closed intervals that meet, [a0, a1] and [b0, b1] with b0 <= a1 and a0 <= b1, get index ranges
// that meet too. Hence two footprints whose closed regions meet (even at one point) always mark a
// common pixel. Footprints marking a common
// pixel are joined (union-find over (pixel, label) pairs sorted by pixel: a sparse raster, so a
// city needs no whole-city allocation). Bounding boxes are coarser than the footprints' shapes;
// that only merges some blocks that the union then splits into separate plans.
//
// City scale: the keys are made and sorted one band of pixel rows at a time (plan_row_bands: at
// most band_keys keys per band, 16M = 128 MiB by default), and the union-find on labels, which
// lives across bands, merges components that cross band edges. Memory is bounded by the band,
// the labels (O(footprints)) and the grid's own bound of ~64 marks per footprint.
#include "blocks/cpu_raster_backend.h"

#include "blocks/raster_common.h"
#include "robust/coordinate_range.h"

#include <groundplan/error.h>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

namespace groundplan {

FootprintSet make_footprint_set(const std::vector<Footprint>& footprints) {
  // Boxes side by side (in the caller's arena), then the admissible ones kept in order.
  std::vector<FootprintSet::Box> boxes(footprints.size());
  std::vector<char> kept(footprints.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, footprints.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      FootprintSet::Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
      bool admissible = true;
      for (const Polygon& p : footprints[i].polygons) {
        auto add = [&](const Ring& ring) {
          for (const Point2& q : ring) {
            if (!robust::admissible(q)) {  // NaN, inf, 1e300, subnormal: the union refuses it (issue 20)
              admissible = false;
              continue;
            }
            b.minx = std::min(b.minx, q.x);
            b.miny = std::min(b.miny, q.y);
            b.maxx = std::max(b.maxx, q.x);
            b.maxy = std::max(b.maxy, q.y);
          }
        };
        add(p.outer);
        for (const Ring& h : p.holes) add(h);
      }
      boxes[i] = b;
      kept[i] = admissible && b.minx <= b.maxx;
    }
  });
  FootprintSet s;
  s.footprints = &footprints;
  s.indices.reserve(footprints.size());
  s.boxes.reserve(footprints.size());
  for (std::uint32_t i = 0; i < footprints.size(); ++i) {
    if (!kept[i]) continue;
    s.indices.push_back(i);
    s.boxes.push_back(boxes[i]);
  }
  return s;
}

PixelGrid make_pixel_grid(const FootprintSet& fps, double resolution_m) {
  PixelGrid g;
  if (fps.boxes.empty()) return g;
  double minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
  double smallest = INFINITY, total_area = 0;
  for (const auto& b : fps.boxes) {
    minx = std::min(minx, b.minx);
    miny = std::min(miny, b.miny);
    maxx = std::max(maxx, b.maxx);
    maxy = std::max(maxy, b.maxy);
    const double w = b.maxx - b.minx, h = b.maxy - b.miny;
    if (w * h > 0) smallest = std::min(smallest, w * h);
    total_area += (w + 0) * (h + 0);
  }
  double res = resolution_m;
  if (!(res > 0)) {
    res = std::isfinite(smallest) ? std::sqrt(smallest / 4.0) : 1.0;  // paper §5
    // keep the marking to ~4 pixels per footprint on average: the raster only groups footprints
    const double budget = 4.0 * static_cast<double>(fps.boxes.size());
    const double coarse = std::sqrt(std::max(total_area, 1e-300) / budget);
    res = std::max(res, coarse);
  }
  // never mark more than ~64 pixels per footprint (+1M): the raster only finds blocks
  for (int guard = 0; guard < 64; ++guard) {
    double marks = 0;
    for (const auto& b : fps.boxes) marks += ((b.maxx - b.minx) / res + 3) * ((b.maxy - b.miny) / res + 3);
    if (marks <= 64.0 * static_cast<double>(fps.boxes.size()) + 1e6) break;
    res *= 2;
  }
  const double span = std::max(maxx - minx, maxy - miny);
  res = std::max(res, span / 2147483000.0);
  if (!(res > 0) || !std::isfinite(res)) res = 1.0;
  g.resolution_m = res;
  g.origin_x = minx - res;
  g.origin_y = miny - res;
  g.width = static_cast<std::int64_t>(std::floor((maxx - g.origin_x) / res)) + 3;
  g.height = static_cast<std::int64_t>(std::floor((maxy - g.origin_y) / res)) + 3;
  return g;
}

namespace detail {
namespace {

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  // the larger root hangs under the smaller: every root is the smallest label of its component
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

std::vector<Block> CpuRasterBackend::find_blocks(const FootprintSet& fps, const PixelGrid& grid,
                                                 const Progress& progress) {
  const std::size_t n = fps.indices.size();
  if (n == 0) return {};
  PixelRanges pr;
  pr.c0.resize(n);
  pr.c1.resize(n);
  pr.r0.resize(n);
  pr.r1.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t i = rg.begin(); i < rg.end(); ++i) {
      const auto& b = fps.boxes[i];
      pr.c0[i] = pixel_index(b.minx, grid.origin_x, grid.resolution_m, grid.width);
      pr.c1[i] = pixel_index(b.maxx, grid.origin_x, grid.resolution_m, grid.width);
      pr.r0[i] = pixel_index(b.miny, grid.origin_y, grid.resolution_m, grid.height);
      pr.r1[i] = pixel_index(b.maxy, grid.origin_y, grid.resolution_m, grid.height);
    }
  });
  const std::vector<RowBand> bands = plan_row_bands(pr, band_keys_);
  UnionFind uf(n);
  const int label_bits = std::max(1, static_cast<int>(std::bit_width(static_cast<std::uint64_t>(n))));
  const std::uint64_t label_mask = (std::uint64_t{1} << label_bits) - 1;
  std::vector<std::uint64_t> offset(n + 1), keys;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> marks;  // when (pixel, label) does not fit 64 bits
  const std::uint64_t width = static_cast<std::uint64_t>(grid.width);
  for (std::size_t bi = 0; bi < bands.size(); ++bi) {
    const RowBand band = bands[bi];
    // keys of each footprint inside the band, then their places (exclusive prefix sum)
    offset[0] = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::int64_t ra = std::max(pr.r0[i], band.row0), rb = std::min(pr.r1[i], band.row1);
      offset[i + 1] = offset[i] + (ra <= rb ? static_cast<std::uint64_t>((rb - ra + 1) * (pr.c1[i] - pr.c0[i] + 1)) : 0);
    }
    const std::uint64_t total = offset[n];
    const std::uint64_t cells = static_cast<std::uint64_t>(band.row1 - band.row0 + 1) * width;
    const bool packed = label_bits + std::bit_width(cells) <= 64;
    auto each_key = [&](auto&& put) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& rg) {
        for (std::size_t i = rg.begin(); i < rg.end(); ++i) {
          std::uint64_t k = offset[i];
          const std::int64_t ra = std::max(pr.r0[i], band.row0), rb = std::min(pr.r1[i], band.row1);
          for (std::int64_t r = ra; r <= rb; ++r)
            for (std::int64_t c = pr.c0[i]; c <= pr.c1[i]; ++c)
              put(k++, static_cast<std::uint64_t>(r - band.row0) * width + static_cast<std::uint64_t>(c),
                  static_cast<std::uint32_t>(i));
        }
      });
    };
    if (packed) {
      // (pixel, label) packed in one 64-bit key: sorting plain integers is several times faster
      keys.resize(total);
      each_key([&](std::uint64_t k, std::uint64_t pixel, std::uint32_t label) { keys[k] = (pixel << label_bits) | label; });
      tbb::parallel_sort(keys.begin(), keys.end());
      for (std::size_t k = 1; k < keys.size(); ++k)
        if ((keys[k] >> label_bits) == (keys[k - 1] >> label_bits))
          uf.join(static_cast<std::uint32_t>(keys[k] & label_mask), static_cast<std::uint32_t>(keys[k - 1] & label_mask));
    } else {
      marks.resize(total);
      each_key([&](std::uint64_t k, std::uint64_t pixel, std::uint32_t label) { marks[k] = {pixel, label}; });
      tbb::parallel_sort(marks.begin(), marks.end());
      for (std::size_t k = 1; k < marks.size(); ++k)
        if (marks[k].first == marks[k - 1].first) uf.join(marks[k].second, marks[k - 1].second);
    }
    progress.report(0.9 * static_cast<double>(bi + 1) / static_cast<double>(bands.size()), "joined pixels");
  }
  keys = {};
  marks = {};
  std::vector<std::uint32_t> root(n);
  for (std::size_t i = 0; i < n; ++i) root[i] = uf.find(static_cast<std::uint32_t>(i));
  return assemble_blocks(fps, root, pr.c1.data(), pr.r1.data());
}

Seeds CpuRasterBackend::find_new_seeds(const FootprintSet& fps, const Block& block,
                                       const std::vector<GroundPlan>& so_far, const PixelGrid& grid) {
  // Pixel-centre sampling of the block's bounding box (paper §3): covered but outside every plan
  // -> another outer boundary; inside a plan but covered by no footprint -> a hole. This finds
  // boundaries larger than a pixel; smaller ones are found by the engine's exact check.
  Seeds s;
  const SeedProblem sp = make_seed_problem(fps, block, so_far, grid);
  const FlatShapes& f = sp.shapes;
  for (std::int64_t r = sp.r0; r <= sp.r1; ++r) {
    for (std::int64_t c = sp.c0; c <= sp.c1; ++c) {
      const double x = grid.origin_x + (static_cast<double>(c) + 0.5) * grid.resolution_m;
      const double y = grid.origin_y + (static_cast<double>(r) + 0.5) * grid.resolution_m;
      bool covered = false, planned = false;
      for (std::uint32_t k = 0; k < sp.n_footprints && !covered; ++k)
        covered = inside_flat_shape(f.shape_first.data(), f.poly_first.data(), f.ring_first.data(), f.xs.data(),
                                    f.ys.data(), k, x, y);
      for (std::uint32_t k = sp.n_footprints; k < f.size() && !planned; ++k)
        planned = inside_flat_shape(f.shape_first.data(), f.poly_first.data(), f.ring_first.data(), f.xs.data(),
                                    f.ys.data(), k, x, y);
      if (covered != planned) s.pixels.push_back({c, r});
    }
  }
  return s;
}

}  // namespace detail
}  // namespace groundplan

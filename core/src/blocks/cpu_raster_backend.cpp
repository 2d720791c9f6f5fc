// SPDX-License-Identifier: MIT
// Blocks from pixels (paper §5) on the CPU. Each footprint marks the pixels of its closed bounding
// box. The marking is conservative without any widening: the pixel index floor((x - origin) / res)
// is a monotone function of x in floating point (subtraction, division by a positive number and
// floor are all monotone under rounding), and it is the same function for every footprint, so two
// closed intervals that meet, [a0, a1] and [b0, b1] with b0 <= a1 and a0 <= b1, get index ranges
// that meet too. Hence two footprints whose closed regions meet (even at one point) always mark a
// common pixel. Footprints marking a common
// pixel are joined (union-find over (pixel, label) pairs sorted by pixel: a sparse raster, so a
// city needs no whole-city allocation). Bounding boxes are coarser than the footprints' shapes;
// that only merges some blocks that the union then splits into separate plans.
#include "blocks/cpu_raster_backend.h"

#include <groundplan/error.h>

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

namespace groundplan {

FootprintSet make_footprint_set(const std::vector<Footprint>& footprints) {
  FootprintSet s;
  s.footprints = &footprints;
  for (std::uint32_t i = 0; i < footprints.size(); ++i) {
    FootprintSet::Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (const Polygon& p : footprints[i].polygons) {
      auto add = [&](const Ring& r) {
        for (const Point2& q : r) {
          if (!std::isfinite(q.x) || !std::isfinite(q.y)) continue;
          b.minx = std::min(b.minx, q.x);
          b.miny = std::min(b.miny, q.y);
          b.maxx = std::max(b.maxx, q.x);
          b.maxy = std::max(b.maxy, q.y);
        }
      };
      add(p.outer);
      for (const Ring& h : p.holes) add(h);
    }
    if (b.minx <= b.maxx) {
      s.indices.push_back(i);
      s.boxes.push_back(b);
    }
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
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

inline std::int64_t pix(double v, double origin, double res, std::int64_t n) {
  return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((v - origin) / res)), 0, n - 1);
}

}  // namespace

std::vector<Block> CpuRasterBackend::find_blocks(const FootprintSet& fps, const PixelGrid& grid,
                                                 const Progress& progress) {
  const std::size_t n = fps.indices.size();
  std::vector<Block> blocks;
  if (n == 0) return blocks;
  struct Mark {
    std::uint64_t pixel;
    std::uint32_t label;
  };
  std::vector<std::int64_t> c0(n), c1(n), r0(n), r1(n);
  std::size_t total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& b = fps.boxes[i];
    c0[i] = pix(b.minx, grid.origin_x, grid.resolution_m, grid.width);
    c1[i] = pix(b.maxx, grid.origin_x, grid.resolution_m, grid.width);
    r0[i] = pix(b.miny, grid.origin_y, grid.resolution_m, grid.height);
    r1[i] = pix(b.maxy, grid.origin_y, grid.resolution_m, grid.height);
    total += static_cast<std::size_t>((c1[i] - c0[i] + 1) * (r1[i] - r0[i] + 1));
  }
  UnionFind uf(n);
  const std::uint64_t cells = static_cast<std::uint64_t>(grid.width) * static_cast<std::uint64_t>(grid.height);
  const int label_bits = std::max(1, static_cast<int>(std::bit_width(static_cast<std::uint64_t>(n))));
  if (label_bits + std::bit_width(cells) <= 64) {
    // (pixel, label) packed in one 64-bit key: sorting plain integers is several times faster
    std::vector<std::uint64_t> keys;
    keys.reserve(total);
    for (std::size_t i = 0; i < n; ++i)
      for (std::int64_t r = r0[i]; r <= r1[i]; ++r)
        for (std::int64_t c = c0[i]; c <= c1[i]; ++c)
          keys.push_back(((static_cast<std::uint64_t>(r) * static_cast<std::uint64_t>(grid.width) +
                           static_cast<std::uint64_t>(c))
                          << label_bits) |
                         i);
    progress.report(0.3, "rasterised footprints");
    tbb::parallel_sort(keys.begin(), keys.end());
    progress.report(0.7, "sorted pixels");
    const std::uint64_t mask = (std::uint64_t{1} << label_bits) - 1;
    for (std::size_t k = 1; k < keys.size(); ++k)
      if ((keys[k] >> label_bits) == (keys[k - 1] >> label_bits))
        uf.join(static_cast<std::uint32_t>(keys[k] & mask), static_cast<std::uint32_t>(keys[k - 1] & mask));
  } else {
    std::vector<Mark> marks;
    marks.reserve(total);
    for (std::size_t i = 0; i < n; ++i)
      for (std::int64_t r = r0[i]; r <= r1[i]; ++r)
        for (std::int64_t c = c0[i]; c <= c1[i]; ++c)
          marks.push_back({static_cast<std::uint64_t>(r) * static_cast<std::uint64_t>(grid.width) +
                               static_cast<std::uint64_t>(c),
                           static_cast<std::uint32_t>(i)});
    progress.report(0.3, "rasterised footprints");
    tbb::parallel_sort(marks.begin(), marks.end(), [](const Mark& a, const Mark& b) { return a.pixel < b.pixel; });
    progress.report(0.7, "sorted pixels");
    for (std::size_t k = 1; k < marks.size(); ++k)
      if (marks[k].pixel == marks[k - 1].pixel) uf.join(marks[k].label, marks[k - 1].label);
  }
  std::vector<std::uint32_t> block_of(n, UINT32_MAX);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t root = uf.find(static_cast<std::uint32_t>(i));
    if (block_of[root] == UINT32_MAX) {
      block_of[root] = static_cast<std::uint32_t>(blocks.size());
      blocks.push_back(Block{{}, -1, -1});
    }
    Block& b = blocks[block_of[root]];
    b.footprints.push_back(fps.indices[i]);
    // rightmost pixel (then topmost) of the block is its first seed (paper §5)
    if (c1[i] > b.seed_col || (c1[i] == b.seed_col && r1[i] > b.seed_row)) {
      b.seed_col = c1[i];
      b.seed_row = r1[i];
    }
  }
  return blocks;
}

namespace {

/// Even-odd test of a pixel centre against one footprint (a hint only: doubles are fine here).
bool inside_footprint(const Footprint& f, double x, double y) {
  bool odd = false;
  for (const Polygon& p : f.polygons) {
    auto ring = [&](const Ring& r) {
      for (std::size_t i = 0, n = r.size(); i < n; ++i) {
        const Point2& a = r[i];
        const Point2& b = r[(i + 1) % n];
        if ((a.y > y) != (b.y > y) && x < a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y)) odd = !odd;
      }
    };
    bool before = odd;
    odd = false;
    ring(p.outer);
    for (const Ring& h : p.holes) ring(h);
    if (odd) return true;
    odd = before;
  }
  return false;
}

bool inside_plan(const GroundPlan& g, double x, double y) {
  Footprint f;
  f.polygons.push_back(g.polygon);
  return inside_footprint(f, x, y);
}

}  // namespace

Seeds CpuRasterBackend::find_new_seeds(const FootprintSet& fps, const Block& block,
                                       const std::vector<GroundPlan>& so_far, const PixelGrid& grid) {
  // Pixel-centre sampling of the block's bounding box (paper §3): covered but outside every plan
  // -> another outer boundary; inside a plan but covered by no footprint -> a hole. This finds
  // boundaries larger than a pixel; smaller ones are found by the engine's exact check.
  Seeds s;
  if (block.footprints.empty()) return s;
  double minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
  for (std::size_t i = 0; i < fps.indices.size(); ++i) {
    if (!std::binary_search(block.footprints.begin(), block.footprints.end(), fps.indices[i])) continue;
    minx = std::min(minx, fps.boxes[i].minx);
    miny = std::min(miny, fps.boxes[i].miny);
    maxx = std::max(maxx, fps.boxes[i].maxx);
    maxy = std::max(maxy, fps.boxes[i].maxy);
  }
  const std::int64_t cx0 = pix(minx, grid.origin_x, grid.resolution_m, grid.width);
  const std::int64_t cx1 = pix(maxx, grid.origin_x, grid.resolution_m, grid.width);
  const std::int64_t cy0 = pix(miny, grid.origin_y, grid.resolution_m, grid.height);
  const std::int64_t cy1 = pix(maxy, grid.origin_y, grid.resolution_m, grid.height);
  const auto& fs = *fps.footprints;
  for (std::int64_t r = cy0; r <= cy1; ++r) {
    for (std::int64_t c = cx0; c <= cx1; ++c) {
      const double x = grid.origin_x + (static_cast<double>(c) + 0.5) * grid.resolution_m;
      const double y = grid.origin_y + (static_cast<double>(r) + 0.5) * grid.resolution_m;
      bool covered = false;
      for (std::uint32_t fi : block.footprints)
        if (inside_footprint(fs[fi], x, y)) {
          covered = true;
          break;
        }
      bool planned = false;
      for (const GroundPlan& g : so_far)
        if (inside_plan(g, x, y)) {
          planned = true;
          break;
        }
      if (covered != planned) s.pixels.push_back({c, r});
    }
  }
  return s;
}

}  // namespace detail
}  // namespace groundplan

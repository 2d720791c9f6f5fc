// SPDX-License-Identifier: MIT
// Host halves shared by the CPU and the CUDA raster backends (raster_common.h).
#include "blocks/raster_common.h"

#include <algorithm>
#include <utility>

namespace groundplan::detail {

void FlatShapes::add_polygon(const Polygon& p) {
  auto ring = [&](const Ring& r) {
    for (const Point2& q : r) {
      xs.push_back(q.x);
      ys.push_back(q.y);
    }
    ring_first.push_back(static_cast<std::uint32_t>(xs.size()));
  };
  ring(p.outer);
  for (const Ring& h : p.holes) ring(h);
  poly_first.push_back(static_cast<std::uint32_t>(ring_first.size() - 1));
}

void FlatShapes::add_footprint(const Footprint& f) {
  for (const Polygon& p : f.polygons) add_polygon(p);
  shape_first.push_back(static_cast<std::uint32_t>(poly_first.size() - 1));
}

void FlatShapes::add_plan(const GroundPlan& g) {
  add_polygon(g.polygon);
  shape_first.push_back(static_cast<std::uint32_t>(poly_first.size() - 1));
}

std::vector<RowBand> plan_row_bands(const PixelRanges& pr, std::uint64_t key_budget) {
  const std::size_t n = pr.c0.size();
  std::vector<RowBand> bands;
  if (n == 0) return bands;
  // keys per row change only where a box starts or ends: sweep those events
  std::vector<std::pair<std::int64_t, std::int64_t>> ev;
  ev.reserve(2 * n);
  std::int64_t last_row = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t w = pr.c1[i] - pr.c0[i] + 1;
    ev.emplace_back(pr.r0[i], w);
    ev.emplace_back(pr.r1[i] + 1, -w);
    last_row = std::max(last_row, pr.r1[i]);
  }
  std::sort(ev.begin(), ev.end());
  key_budget = std::max<std::uint64_t>(key_budget, 1);
  std::int64_t band_start = ev.front().first, row = band_start;
  std::uint64_t acc = 0, cur = 0;
  std::size_t e = 0;
  while (e < ev.size()) {
    while (e < ev.size() && ev[e].first == row) cur = static_cast<std::uint64_t>(static_cast<std::int64_t>(cur) + ev[e++].second);
    if (e == ev.size()) break;  // past the last box: cur == 0
    const std::int64_t next = ev[e].first;
    for (std::int64_t r = row; r < next;) {
      if (cur == 0) break;  // empty rows cost nothing
      const std::uint64_t room = acc >= key_budget ? 0 : key_budget - acc;
      std::uint64_t fit = room / cur;
      if (fit == 0) {
        if (acc != 0) {  // close the band before row r
          bands.push_back({band_start, r - 1});
          band_start = r;
          acc = 0;
          continue;
        }
        fit = 1;  // a single row over the budget is a band of its own
      }
      const std::int64_t take = static_cast<std::int64_t>(std::min<std::uint64_t>(fit, static_cast<std::uint64_t>(next - r)));
      acc += static_cast<std::uint64_t>(take) * cur;
      r += take;
    }
    row = next;
  }
  bands.push_back({band_start, last_row});
  return bands;
}

std::vector<Block> assemble_blocks(const FootprintSet& fps, const std::vector<std::uint32_t>& root,
                                   const std::int64_t* c1, const std::int64_t* r1) {
  const std::size_t n = root.size();
  std::vector<std::uint32_t> block_of(n, UINT32_MAX), count;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t& b = block_of[root[i]];
    if (b == UINT32_MAX) {
      b = static_cast<std::uint32_t>(count.size());
      count.push_back(0);
    }
    ++count[b];
  }
  std::vector<Block> blocks(count.size(), Block{{}, -1, -1});
  for (std::size_t b = 0; b < blocks.size(); ++b) blocks[b].footprints.reserve(count[b]);
  for (std::size_t i = 0; i < n; ++i) {
    Block& b = blocks[block_of[root[i]]];
    b.footprints.push_back(fps.indices[i]);
    // rightmost pixel (then topmost) of the block is its first seed (paper §5)
    if (c1[i] > b.seed_col || (c1[i] == b.seed_col && r1[i] > b.seed_row)) {
      b.seed_col = c1[i];
      b.seed_row = r1[i];
    }
  }
  return blocks;
}

SeedProblem make_seed_problem(const FootprintSet& fps, const Block& block, const std::vector<GroundPlan>& so_far,
                              const PixelGrid& grid) {
  SeedProblem sp;
  if (block.footprints.empty()) return sp;
  double minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
  for (std::uint32_t fi : block.footprints) {  // O(block log n), not O(n) per block
    const auto it = std::lower_bound(fps.indices.begin(), fps.indices.end(), fi);
    if (it == fps.indices.end() || *it != fi) continue;
    const std::size_t i = static_cast<std::size_t>(it - fps.indices.begin());
    minx = std::min(minx, fps.boxes[i].minx);
    miny = std::min(miny, fps.boxes[i].miny);
    maxx = std::max(maxx, fps.boxes[i].maxx);
    maxy = std::max(maxy, fps.boxes[i].maxy);
  }
  if (!(minx <= maxx)) return sp;
  sp.c0 = pixel_index(minx, grid.origin_x, grid.resolution_m, grid.width);
  sp.c1 = pixel_index(maxx, grid.origin_x, grid.resolution_m, grid.width);
  sp.r0 = pixel_index(miny, grid.origin_y, grid.resolution_m, grid.height);
  sp.r1 = pixel_index(maxy, grid.origin_y, grid.resolution_m, grid.height);
  const auto& fs = *fps.footprints;
  for (std::uint32_t fi : block.footprints) sp.shapes.add_footprint(fs[fi]);
  sp.n_footprints = sp.shapes.size();
  for (const GroundPlan& g : so_far) sp.shapes.add_plan(g);
  return sp;
}

}  // namespace groundplan::detail

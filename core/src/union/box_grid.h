// SPDX-License-Identifier: MIT
#pragma once
// A uniform grid of boxes for candidate queries, shared by the boundary walk (block_union.cpp: polygons
// near an edge) and snap rounding (snap_round.cpp: hot pixels, edges, rings near one another).
#include "union/block_types.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace groundplan::detail {

/// Uniform grid of boxes (edges or polygons) for candidate queries. Cell indices are computed
/// monotonically from coordinates, so a point inside a box always falls in one of its cells.
class BoxGrid {
 public:
  void build(const std::vector<Box>& boxes, const Box& all, std::size_t target_cells) {
    ox_ = all.minx;
    oy_ = all.miny;
    const double w = std::max(all.maxx - all.minx, 1e-300), h = std::max(all.maxy - all.miny, 1e-300);
    const double cell = std::sqrt(w * h / static_cast<double>(std::max<std::size_t>(target_cells, 1)));
    const double c = cell > 0 && std::isfinite(cell) ? cell : std::max(w, h);
    nx_ = static_cast<int>(std::clamp(std::ceil(w / c), 1.0, 2048.0));
    ny_ = static_cast<int>(std::clamp(std::ceil(h / c), 1.0, 2048.0));
    ix_ = nx_ / w;
    iy_ = ny_ / h;
    start_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
    for (const Box& b : boxes) for_cells(b, [&](std::size_t k) { ++start_[k + 1]; });
    for (std::size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
    items_.resize(start_.back());
    fill_.assign(start_.begin(), start_.end() - 1);
    std::vector<std::uint32_t>& fill = fill_;
    for (std::uint32_t i = 0; i < boxes.size(); ++i) for_cells(boxes[i], [&](std::size_t k) { items_[fill[k]++] = i; });
    stamp_.assign(boxes.size(), 0);
  }
  /// Calls f(item) once for every item whose cells meet box b.
  template <class F>
  void query(const Box& b, F&& f) {
    if (++epoch_ == 0) {
      std::fill(stamp_.begin(), stamp_.end(), 0);
      epoch_ = 1;
    }
    for_cells(b, [&](std::size_t k) {
      for (std::uint32_t i = start_[k]; i < start_[k + 1]; ++i) {
        const std::uint32_t it = items_[i];
        if (stamp_[it] != epoch_) {
          stamp_[it] = epoch_;
          f(it);
        }
      }
    });
  }

 private:
  // Clamped before the conversion: a query box may lie far outside the grid (no int overflow).
  int cx(double x) const { return static_cast<int>(std::clamp(std::floor((x - ox_) * ix_), 0.0, nx_ - 1.0)); }
  int cy(double y) const { return static_cast<int>(std::clamp(std::floor((y - oy_) * iy_), 0.0, ny_ - 1.0)); }
  template <class F>
  void for_cells(const Box& b, F&& f) const {
    const int x0 = cx(b.minx), x1 = cx(b.maxx), y0 = cy(b.miny), y1 = cy(b.maxy);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) f(static_cast<std::size_t>(y) * nx_ + x);
  }
  double ox_ = 0, oy_ = 0, ix_ = 1, iy_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::uint32_t> start_, items_, stamp_, fill_;
  std::uint32_t epoch_ = 0;
};

}  // namespace groundplan::detail

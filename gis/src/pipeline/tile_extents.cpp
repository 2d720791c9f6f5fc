// SPDX-License-Identifier: MIT
#include "pipeline/tile_extents.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace groundplan::gis::detail {

Box empty_box() {
  const double inf = std::numeric_limits<double>::infinity();
  return {inf, inf, -inf, -inf};
}

void grow(Box& b, double x, double y) {
  b[0] = std::min(b[0], x);
  b[1] = std::min(b[1], y);
  b[2] = std::max(b[2], x);
  b[3] = std::max(b[3], y);
}

bool boxes_meet(const Box& a, const Box& b) {
  if (a[0] > a[2] || b[0] > b[2]) return false;
  return a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3];
}

TileExtents::TileExtents(std::vector<Box> extents) : extents_(std::move(extents)) {
  std::vector<double> sides;
  for (const Box& b : extents_) {
    if (b[0] > b[2]) continue;
    grow(all_, b[0], b[1]);
    grow(all_, b[2], b[3]);
    sides.push_back(std::max(b[2] - b[0], b[3] - b[1]));
  }
  if (sides.empty()) return;
  // A cell about the median tile: a tile covers a few cells, a cell holds a few tiles.
  std::nth_element(sides.begin(), sides.begin() + static_cast<std::ptrdiff_t>(sides.size() / 2), sides.end());
  const double span = std::max(all_[2] - all_[0], all_[3] - all_[1]);
  cell_ = std::max({sides[sides.size() / 2], span / 4096.0, 1e-9});
  nx_ = static_cast<std::int64_t>(std::floor((all_[2] - all_[0]) / cell_)) + 1;
  ny_ = static_cast<std::int64_t>(std::floor((all_[3] - all_[1]) / cell_)) + 1;
  cells_.resize(static_cast<std::size_t>(nx_ * ny_));
  for (std::uint32_t t = 0; t < extents_.size(); ++t) {
    const Box& b = extents_[t];
    if (b[0] > b[2]) continue;
    std::int64_t x0, y0, x1, y1;
    cell_range(b, x0, y0, x1, y1);
    if ((x1 - x0 + 1) * (y1 - y0 + 1) > 64) {
      large_.push_back(t);
      continue;
    }
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) cells_[static_cast<std::size_t>(y * nx_ + x)].push_back(t);
  }
}

void TileExtents::cell_range(const Box& b, std::int64_t& x0, std::int64_t& y0, std::int64_t& x1,
                             std::int64_t& y1) const {
  auto clamp = [](double v, std::int64_t n) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(v)), 0, n - 1);
  };
  x0 = clamp((b[0] - all_[0]) / cell_, nx_);
  y0 = clamp((b[1] - all_[1]) / cell_, ny_);
  x1 = clamp((b[2] - all_[0]) / cell_, nx_);
  y1 = clamp((b[3] - all_[1]) / cell_, ny_);
}

bool TileExtents::meets_outside(const Box& box, std::uint32_t first, std::uint32_t last) const {
  auto outside = [&](std::uint32_t t) { return t < first || t >= last; };
  if (!boxes_meet(box, all_)) return false;
  for (std::uint32_t t : large_)
    if (outside(t) && boxes_meet(box, extents_[t])) return true;
  std::int64_t x0, y0, x1, y1;
  cell_range(box, x0, y0, x1, y1);
  for (std::int64_t y = y0; y <= y1; ++y)
    for (std::int64_t x = x0; x <= x1; ++x)
      for (std::uint32_t t : cells_[static_cast<std::size_t>(y * nx_ + x)])
        if (outside(t) && boxes_meet(box, extents_[t])) return true;
  return false;
}

}  // namespace groundplan::gis::detail

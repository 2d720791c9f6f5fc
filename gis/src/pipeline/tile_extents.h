// SPDX-License-Identifier: MIT
#pragma once
// The tiles' extents (bounding boxes of their footprints, working CRS) and the question the reduce asks of
// each tile plan: does its box meet any other tile's extent? A uniform grid over the extents, so that the
// question costs a few boxes, not one a tile.
#include <array>
#include <cstdint>
#include <vector>

namespace groundplan::gis::detail {

using Box = std::array<double, 4>;  // xmin, ymin, xmax, ymax; xmin > xmax: empty

/// An empty box (meets nothing) to grow with grow().
Box empty_box();
void grow(Box& b, double x, double y);
/// Closed boxes: touching counts as meeting (a footprint on the edge of another tile's extent may touch).
bool boxes_meet(const Box& a, const Box& b);

class TileExtents {
 public:
  /// `extents[t]`: tile t's extent (empty for a tile without footprints).
  explicit TileExtents(std::vector<Box> extents);
  /// True when `box` meets the extent of a tile other than `own`.
  bool meets_other(const Box& box, std::uint32_t own) const { return meets_outside(box, own, own + 1); }
  /// True when `box` meets the extent of a tile outside [first, last): the tiles a group of ranks has mapped
  /// (the reduce tree's question).
  bool meets_outside(const Box& box, std::uint32_t first, std::uint32_t last) const;
  std::size_t size() const { return extents_.size(); }

 private:
  std::vector<Box> extents_;
  Box all_ = empty_box();
  double cell_ = 1;
  std::int64_t nx_ = 0, ny_ = 0;
  std::vector<std::vector<std::uint32_t>> cells_;
  std::vector<std::uint32_t> large_;  // tiles covering too many cells: checked one by one
  void cell_range(const Box& b, std::int64_t& x0, std::int64_t& y0, std::int64_t& x1, std::int64_t& y1) const;
};

}  // namespace groundplan::gis::detail

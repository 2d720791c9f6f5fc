// SPDX-License-Identifier: MIT
#pragma once
// Types shared by the block engine (block_union.cpp), the ring builder and the output rounding:
// input edges and polygons of one block, their boxes, and the closed walks the engine traces.
#include <groundplan/types.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace groundplan::detail {

struct Box {
  double minx = std::numeric_limits<double>::infinity(), miny = std::numeric_limits<double>::infinity();
  double maxx = -std::numeric_limits<double>::infinity(), maxy = -std::numeric_limits<double>::infinity();
  void add(const Point2& p) {
    minx = std::min(minx, p.x);
    miny = std::min(miny, p.y);
    maxx = std::max(maxx, p.x);
    maxy = std::max(maxy, p.y);
  }
  void grow(double d) {  // by d on every side
    minx -= d;
    miny -= d;
    maxx += d;
    maxy += d;
  }
  bool overlaps(const Box& o) const { return minx <= o.maxx && o.minx <= maxx && miny <= o.maxy && o.miny <= maxy; }
  bool contains(const Point2& p) const { return minx <= p.x && p.x <= maxx && miny <= p.y && p.y <= maxy; }
};

struct Edge {
  Point2 p0, p1;
  std::uint32_t poly;
};

struct Poly {
  std::uint32_t footprint;
  std::uint32_t first_edge, end_edge;
  Box box;
  bool has_area;
};

/// What a walk vertex is exactly, for snap rounding: the segment ending at it lies on the line a->b (the input
/// edge walked, in the walk's direction), and a crossing point is where that line meets the line f0->f1.
struct ExactVertex {
  Point2 a, b, f0, f1;
  bool cross;
};

struct RingOut {
  std::vector<Point2> pts;
  bool rounded = false;  // some vertex is a rounded crossing point (else every vertex is exact input)
  std::vector<std::uint32_t> polys;  // polygons whose area borders this ring
  // Per vertex of pts, what it is exactly; filled for rounded walks only (the others are exact as they are).
  // A rounded walk without it is taken as its rounded points (snap_round's unit tests).
  std::vector<ExactVertex> exact;
};

inline int sgn_diff(double a, double b) { return (a > b) - (a < b); }

/// Two parallel directions point the same way.
inline bool same_way(const Point2& u0, const Point2& u1, const Point2& v0, const Point2& v1) {
  return sgn_diff(u1.x, u0.x) == sgn_diff(v1.x, v0.x) && sgn_diff(u1.y, u0.y) == sgn_diff(v1.y, v0.y);
}

}  // namespace groundplan::detail

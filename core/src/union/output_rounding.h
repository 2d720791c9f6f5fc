// SPDX-License-Identifier: MIT
#pragma once
// Output rounding (issue 3, issue 20): exact checks and local repairs of rings whose vertices
// include rounded crossing points (robust predicates on the doubles). Moved out of block_union.cpp.
#include <groundplan/types.h>

#include <cstddef>
#include <initializer_list>
#include <vector>

namespace groundplan::detail {

long double signed_area2(const std::vector<Point2>& r);
int ring_orientation(const std::vector<Point2>& r);
int point_in_ring(const Point2& p, const std::vector<Point2>& r);
double rounding_scale(std::initializer_list<Point2> pts);
struct Conflict {
  std::size_t ring_a, edge_a, ring_b, edge_b;
};
bool find_conflict(const std::vector<std::vector<Point2>*>& rings, Conflict& c);
bool repair_once(std::vector<std::vector<Point2>*>& rings, const Conflict& c);
long double dist_to_segment(const Point2& p, const Point2& a, const Point2& b);
bool node_walk(std::vector<Point2>& w);

}  // namespace groundplan::detail

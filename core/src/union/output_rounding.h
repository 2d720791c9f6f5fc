// SPDX-License-Identifier: MIT
#pragma once
// Exact measures and checks of output rings on their doubles (robust predicates): area, orientation,
// point location, and the validity check that guards snap-rounded plans (issue 3, issue 20).
#include <groundplan/types.h>

#include <cstddef>
#include <initializer_list>
#include <vector>

namespace groundplan::detail {

long double signed_area2(const std::vector<Point2>& r);
int ring_orientation(const std::vector<Point2>& r);
int point_in_ring(const Point2& p, const std::vector<Point2>& r);
struct Conflict {
  std::size_t ring_a, edge_a, ring_b, edge_b;
};
bool find_conflict(const std::vector<std::vector<Point2>*>& rings, Conflict& c);

}  // namespace groundplan::detail

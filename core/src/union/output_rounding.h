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
/// Whether rings that touch one another at points (a vertex of one equal to a vertex of, or on an edge
/// of, another) close a cycle through a hole (a clockwise ring): a hole touching its shell at two
/// points, or a chain of holes touching back to the shell. Within one plan that is OGC's "interior is
/// disconnected"; a cycle of shells only (plans sharing two vertices) is valid and not reported. Rings
/// are "union on the left" (holes clockwise); a ring touching itself is find_conflict's concern.
bool touch_cycle(const std::vector<std::vector<Point2>*>& rings);

/// Rings whose orientation contradicts their nesting, for the rings flagged in `subject` (others get 0).
/// Union on the left: an outer ring (counter-clockwise) lies strictly inside an even number of the other
/// rings (none, or an outer ring and one of its holes), a hole (clockwise) inside an odd number. A ring
/// narrower than an ulp somewhere can turn over when its computed vertices are rounded: a sliver hole
/// then comes out as an outer ring lying inside another plan, which crosses no edge and touches no ring
/// (fuzz regression e393fd6c), or a sliver island as a hole inside another hole. Exact on the doubles;
/// a ring all of whose vertices lie on another ring is not counted inside it.
std::vector<char> nesting_flips(const std::vector<std::vector<Point2>>& rings, const std::vector<char>& subject);

}  // namespace groundplan::detail

// SPDX-License-Identifier: MIT
#pragma once
// Which footprints the union can take (issue 20: a total API). Any input is answered: a footprint
// with a coordinate the predicates are not certified for (robust/coordinate_range.h: NaN, ±inf,
// magnitudes beyond 2^50 or nonzero below 2^-150) or without three non-collinear points is a
// Problem (stage "union") naming it, and takes no part; the rest is computed as usual.
#include <groundplan/types.h>

#include <vector>

namespace groundplan::detail {

/// One entry per footprint: 1 when the union takes it. Appends one Problem per refused footprint:
/// NOT_FINITE or COORDINATE_OUT_OF_RANGE (naming polygon, ring, vertex and value), else NO_AREA.
std::vector<char> usable_footprints(const std::vector<Footprint>& footprints, std::vector<Problem>& problems);

/// True when every coordinate of the footprint is admissible (robust::admissible).
bool coordinates_admissible(const Footprint& footprint);

}  // namespace groundplan::detail

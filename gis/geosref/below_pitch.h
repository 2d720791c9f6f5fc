// SPDX-License-Identifier: MIT
#pragma once
// Whether plans differ from GEOS's exact union only by features narrower than the union's snap pitch
// (issue 20: output vertices closer than the pitch g are one vertex, so gaps and necks narrower than it
// close and holes narrower than it collapse; GEOS's exact union keeps them). Used by compare_with_geos
// where the polygon or hole counts or the areas differ, so by `groundplan --verify` and by the tests.
#include <groundplan/types.h>

#include <geos_c.h>

#include <string>
#include <vector>

namespace groundplan::gis::detail {

struct BelowPitch {
  bool all = true;        // every difference is narrower than w
  std::string first_not;  // where one is not, for a person
};

/// Snap rounding moves a vertex by at most g/sqrt(2): two pieces up to g sqrt(2) apart can meet, and a
/// feature up to that wide can collapse. So with w = 1.5 g, the plans and GEOS's polygons must differ only by
/// material narrower than w: each piece of their symmetric difference, shrunk by w/2, leaves nothing, or is a
/// sliver (twice its area over its perimeter at most w/2; GEOS's buffer cannot erase slivers a few ulps
/// wide reliably). A plan count can then
/// differ only where a gap (joined), a neck (split) or a hole (collapsed, closed off by a gap, or let out
/// through a neck) narrower than w made it differ; the area by up to w times the length of such features.
/// Computed about a local origin, so that widths of 1e-8 m at coordinates of 1e6 m are resolved.
/// One piece of a symmetric difference (its coordinates about a local origin, see below) is narrower than w:
/// shrinking it by w/2 leaves nothing, or twice its area over its perimeter (its width, for a sliver) is at
/// most w/2.
bool narrower_than(GEOSContextHandle_t h, const GEOSGeometry* piece, double w);

BelowPitch differences_below_pitch(const std::vector<Polygon>& ours, const std::vector<Polygon>& geos, double pitch);

}  // namespace groundplan::gis::detail

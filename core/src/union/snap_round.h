// SPDX-License-Identifier: MIT
#pragma once
// Snap rounding of one block's boundary (issue 20; docs/union_engine.md, "Snap rounding").
// The engine's walks are exact up to their crossing points, each correctly rounded to doubles.
// Rounded, two walks may cross, overlap by a sliver or pass within an ulp of each other. This stage
// makes the output consistent: iterated snap rounding (ISR, Halperin & Packer) of the walks' exact
// segments (RingOut::exact: the input edge each lies on, the exact pixel of each crossing)
// on one grid of pitch g for the whole call, cancellation of opposite coincident grid edges, and
// rings linked by the engine's minimal-ring rule.
#include <cstdint>
#include <vector>

#include "union/block_types.h"

namespace groundplan::detail {

/// The grid pitch for coordinates of magnitude at most `max_abs`: 16 ulp(max_abs), a power of two.
/// Pixel sides, centres and their differences are then exact doubles; a pixel centre is at least
/// g/2 = 8 ulp from every rounded edge that does not pass through its pixel (the ISR guarantee).
double snap_pitch(double max_abs);

struct SnappedRing {
  std::vector<Point2> pts;            // closed, no repeated vertex, union on the left
  std::vector<std::uint32_t> polys;   // polygons of the walks whose edges form this ring
};

struct SnapStats {
  std::uint64_t hot_pixels = 0;
  std::uint64_t cancelled = 0;   // pairs of opposite coincident grid edges removed (collapsed features)
  std::uint64_t exact_fallbacks = 0;  // kept input vertices failed the exact check: all moved to centres
};

/// Groups the walks of a block by proximity: two walks are in one group when boxes of their segments,
/// grown by 4 pitches, overlap (transitively). Groups are then more than 4 pitches apart, so the
/// snap rounding of one (which moves its vertices by less than a pitch) never meets another, and a
/// group without crossing points can be output exactly. Returns a group id per walk, 0..n-1.
std::vector<std::uint32_t> proximity_groups(const std::vector<RingOut>& walks, double pitch);

/// Whether simple rings on their doubles (the walks split, crossings correctly rounded) are valid and
/// disjoint: no two edges cross or overlap, no ring touches itself, no hole touches its shell twice.
/// With `near`, also that they do not near-touch (near_touching). Then snap rounding is not needed and
/// would only move them.
bool clean_as_rounded(const std::vector<std::vector<Point2>>& rings, double pitch, bool near);
/// clean_as_rounded without `near` on the rings flagged `rounded` and the others whose boxes come within a
/// pitch of one of them (exact rings cannot cross each other).
bool clean_near_rounded(const std::vector<std::vector<Point2>>& rings, const std::vector<char>& rounded, double pitch);

/// Whether two distinct vertices of `rings` are within a pitch of each other (in x and in y), or a vertex
/// is within a pitch of the interior of an edge without being exactly on it. Output vertices that close
/// are one vertex after snap rounding (issue 20: "output vertices closer than δ are one vertex"), whether
/// the union computed them or the input had them; exact contact (equal vertices, a vertex exactly on an
/// edge) is how OGC plans touch, and stays.
bool near_touching(const std::vector<std::vector<Point2>>& rings, double pitch);

/// Snap-rounds the closed walks of one block on the grid of pitch `pitch`. Returns false (and
/// leaves `out` empty) only if the rounded boundary is not a consistent edge graph, which the
/// construction rules out; the caller then reports ROUNDING_INVALID.
bool snap_round(const std::vector<RingOut>& walks, double pitch, std::vector<SnappedRing>& out, SnapStats& stats);

}  // namespace groundplan::detail

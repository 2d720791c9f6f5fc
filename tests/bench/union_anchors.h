// SPDX-License-Identifier: MIT
#pragma once
// Other libraries' unions as anchors for bench_union: Clipper2 (one Union call of every path, and one Union per
// group of footprints whose boxes meet, found by a sweep and union-find, as a user of Clipper2 would write it) and
// Boost.Polygon (one polygon set of everything). Benchmark only: Clipper2 is built from a source tree given at
// configure time (tests/bench/union_anchors.sh fetches nothing; it takes the tree you point it at), Boost.Polygon
// from Debian's libboost-dev headers. Neither library is part of groundplan.
//
// Input: the footprints as integers, micrometres (llround(x * 1e6)), outer rings counter-clockwise and holes
// clockwise for Clipper2's NonZero rule. The conversion is made once, before the timed runs, so the anchors are
// timed on their union alone (and the grouping, for the per-group variant): the strictest comparison for us.
#include <groundplan/types.h>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace groundplan::bench {

struct Anchor {
  virtual ~Anchor() = default;
  /// One union of everything prepared; returns the number of polygons (outer rings) of the result.
  virtual std::size_t run() = 0;
};

/// "clipper2" (one call), "clipper2_groups" (per box-connected group), "boost" (Boost.Polygon); nullptr with
/// `why` set when the anchor was not built in (configure with GROUNDPLAN_BENCH_CLIPPER2_DIR / libboost-dev).
std::unique_ptr<Anchor> make_anchor(const std::string& name, const std::vector<Footprint>& footprints,
                                    std::string& why);

}  // namespace groundplan::bench

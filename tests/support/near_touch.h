// SPDX-License-Identifier: MIT
#pragma once
// Near-touch artefacts of rounding (issue 20), a check shared by the tests: two distinct output
// vertices within a few units in the last place of each other, or a vertex within that distance of
// an edge it is not exactly on (one crossing rounded twice: micro-edges ~1e-15 relative, or pieces
// joined by a zero-width gap). Exact contact (equal vertices, a vertex exactly on an edge) is not an
// artefact: that is how OGC plans touch.
#include <groundplan/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace groundplan::testing {

struct NearTouch {
  std::size_t pairs = 0;  // vertex-vertex and vertex-edge pairs found
  std::string first;      // a description of the first, for messages
  /// With the input given: the pairs in which the union computed a point (a vertex of the pair, or an
  /// end of the edge, is no input vertex), the "artefact" proper, and the first of them. The
  /// other pairs are made of input vertices and edges alone: the input near-touches there already
  /// (a T-junction one ulp off its wall after an inexact rotation), and the exact union keeps it.
  std::size_t computed = 0;
  std::string first_computed;
};

/// Over all rings of all plans. Distance threshold: `ulps` units in the last place of the larger
/// coordinate magnitude involved. `input` (optional): the footprints the plans were made of, to tell
/// computed pairs from pairs of input vertices (NearTouch::computed).
NearTouch near_touch(const std::vector<GroundPlan>& plans, double ulps = 8,
                     const std::vector<Footprint>* input = nullptr);

}  // namespace groundplan::testing

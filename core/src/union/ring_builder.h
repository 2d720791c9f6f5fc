// SPDX-License-Identifier: MIT
#pragma once
// Ring builder: the engine's closed walks -> simple rings -> ground plans (outer ring with its
// holes and members). Moved out of block_union.cpp.
#include <vector>

#include "union/block_types.h"
#include "union/block_union.h"

namespace groundplan::detail {

/// Splits a closed walk at repeated vertices into simple rings; drops spikes and straight vertices.
void split_simple(const std::vector<Point2>& walk, std::vector<std::vector<Point2>>& out);

/// The plans of one block from its closed walks: exact walks split into simple rings, or, where a walk
/// has a rounded crossing point, the whole block snap-rounded on the grid of pitch `pitch`
/// (snap_round.h); then the rings are oriented, each hole put into the innermost outer ring
/// containing it, and the members found.
void assemble_block(const std::vector<RingOut>& rings, const std::vector<Poly>& polys,
                    const std::vector<Edge>& edges, double pitch, BlockStats& stats, BlockResult& out);

}  // namespace groundplan::detail

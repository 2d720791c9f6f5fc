// SPDX-License-Identifier: MIT
#pragma once
// Ring builder: the engine's closed walks -> simple rings -> ground plans (outer ring with its
// holes and members). Moved out of block_union.cpp.
#include <vector>

#include "union/block_types.h"
#include "union/block_union.h"

namespace groundplan::detail {

/// Splits a closed walk at repeated (rounded) vertices into simple rings; drops collapsed parts.
void split_simple(const std::vector<Point2>& walk, std::vector<std::vector<Point2>>& out, bool rounded);

/// The plans of one block from its closed walks: node and split each walk, orient the rings, put
/// each hole into the innermost outer ring containing it, find the members, check the rounded plans.
void assemble_block(const std::vector<RingOut>& rings, const std::vector<Poly>& polys,
                    const std::vector<Edge>& edges, BlockStats& stats, BlockResult& out);

}  // namespace groundplan::detail

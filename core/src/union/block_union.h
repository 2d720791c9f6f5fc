// SPDX-License-Identifier: MIT
#pragma once
// The union of one block of footprints by online boundary evaluation (paper §6), with the exact
// completeness check that replaces pixel resolution (paper §3 "Update", issue 3).
#include <groundplan/types.h>

#include <cstdint>
#include <vector>

namespace groundplan::detail {

struct BlockStats {
  std::uint64_t walk_steps = 0;      // boundary edges discovered (§6.2 iterations)
  std::uint64_t rings_traced = 0;    // closed boundary walks
  std::uint64_t seeds_from_check = 0;// walks started by the completeness check (holes, separate rings)
  std::uint64_t edges_checked = 0;   // input edges the completeness check had to examine exactly
  std::uint64_t rounding_repairs = 0;// snap rounding: opposite grid edges cancelled (collapsed slivers)
  std::uint64_t snapped_groups = 0;  // groups of walks snap-rounded (they had a crossing point)
  std::uint64_t simple_rings = 0;    // 1 where the walks were the block's rings themselves (the shortcut)
};

struct BlockResult {
  std::vector<GroundPlan> plans;
  std::vector<Problem> problems;
  BlockStats stats;
  std::vector<std::uint32_t> snapped;  // footprints bordering a snap-rounded group (for the message of one
                                       // that collapsed: narrower than the pitch, in no plan)
  double pitch = 0;                    // the block's snap-rounding grid
};

/// The exact union of the footprints `members` (indices into `footprints`): one GroundPlan per
/// connected polygon, outer ring counter-clockwise, holes clockwise. Each input polygon counts by
/// the even-odd rule over its rings (its valid repair, as GEOS MakeValid gives it). Throws
/// TopologyError if a boundary walk does not close (never expected: every decision is exact).
/// `pitch`: the block's snap-rounding grid (snap_pitch of its largest coordinate magnitude), used where
/// the block's boundary as rounded is not clean or near-touches (snap_round.h).
/// `shortcut`: rings that neither touch nor cross one another or themselves, in polygons whose boxes are apart,
/// are taken as the walks without walking them (the same walks, found in the same order; the usual detached
/// building). false only for the tests that compare the two.
BlockResult union_block(const std::vector<Footprint>& footprints, const std::vector<std::uint32_t>& members,
                        double pitch, bool shortcut = true);

}  // namespace groundplan::detail

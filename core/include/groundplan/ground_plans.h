// SPDX-License-Identifier: MIT
#pragma once
// The union stage: footprints in, non-overlapping ground plans out (paper §3, §5, §6).
#include <groundplan/progress.h>
#include <groundplan/types.h>
#include <string>
#include <vector>

namespace groundplan {

enum class Device { Auto, Cpu, Cuda };

/// What the union stage did, for --stats (filled when UnionParams::stats is set).
struct UnionStats {
  std::size_t blocks = 0;       // blocks found by the raster backend (paper §5)
  double blocks_s = 0;          // time to find them, starting the backend included (CUDA: ~0.3 s)
  double union_s = 0;           // time for the boundary evaluation of all blocks (§6)
  std::string backend;          // "cpu" or "cuda"
};

/// Where the plans can go while later blocks are still being united (issue 14: a writer that starts before the union
/// ends). The plans of the result are the blocks' plans in block order; a feed is told each block's plans as soon as
/// that block is united, from the union's threads, in any order: it must be thread-safe. The result is unchanged.
class PlanFeed {
 public:
  virtual ~PlanFeed() = default;
  /// Once, before any block is united: how many blocks there are.
  virtual void begin(std::size_t blocks) = 0;
  /// Block `b`'s plans, in their order in the result (after every plan of the blocks before b); once a block.
  virtual void block_done(std::size_t b, const std::vector<GroundPlan>& plans) = 0;
  /// Once, last, also when the union stops early (an exception, a cancel): `complete` false then.
  virtual void end(bool complete) = 0;
};

struct UnionParams {
  double resolution_m = 0;     // raster pixel for blocks/seeds; 0 = automatic (paper §5). Exactness never depends on it.
  Device device = Device::Auto;
  int threads = 0;             // 0 = all cores
  UnionStats* stats = nullptr; // out, optional
  PlanFeed* feed = nullptr;    // optional: told the plans block by block (see PlanFeed); not with a level of detail
};

/// The exact union of `footprints` (working CRS, metres), one GroundPlan per connected region.
/// Output rings: outer CCW, holes CW, no repeated points, valid by OGC rules (GEOS isValid).
/// Members list every footprint index that contributes area to the plan. A footprint with no
/// usable area (all polygons degenerate) is reported in `problems` (stage "union") and is in no plan.
/// Any footprint is accepted (issue 20): one with a coordinate that is NaN or infinite (`NOT_FINITE`),
/// or nonzero with a magnitude outside [2^-150, 2^50] m (`COORDINATE_OUT_OF_RANGE`: ±1e300,
/// subnormals; the range in which the exact predicates are certified) is a Problem naming its
/// source id and the vertex, and is in no plan; empty footprints, 1- and 2-point rings and repeated
/// points are allowed. Throws InvalidArgument for bad params, Cancelled if `progress` asks to stop.
std::vector<GroundPlan> build_ground_plans(const std::vector<Footprint>& footprints, const UnionParams& params,
                                           std::vector<Problem>& problems, const Progress& progress = {});

/// The grid of the union's snap rounding (issue 20, docs/union_engine.md "Snap rounding") for coordinates of
/// magnitude up to `max_abs`: 16 units in the last place of max_abs, a power of two (1.5e-8 m at UTM
/// northings). Output vertices closer than it are one vertex, and features narrower than it collapse;
/// each block of touching footprints is rounded on the pitch of its own largest coordinate.
double snap_pitch(double max_abs);

}  // namespace groundplan

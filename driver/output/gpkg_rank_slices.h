// SPDX-License-Identifier: MIT
#pragma once
// `mpirun -np N groundplan ... -f GPKG new.gpkg` (issue 15): every rank writes its own final plans into a GeoPackage
// slice of its own, side by side, instead of streaming them to rank 0 to be written by one GDAL writer (3-4 s of a
// 7.5 s run at 16 ranks, tests/bench/RESULTS.md). Rank 0 writes the destination itself (its own plans and members,
// and the problems); rank r > 0 writes `.<name>.rank<r>-<id>.gpkg` into a folder rank 0 names (its staging folder
// beside the destination, which every rank must see: the CLI checks that before the run, and gathers the plans to
// rank 0 where it does not hold). Every feature keeps the id rank 0 would give it when gathering
// (TiledResult::plan_number/row_number, ogr2ogr -preserve_fid), so rank 0 then appends the slices' rows in FID
// order (gpkg_slices.h append_runs: INSERT ... SELECT, extent, feature count, triggers) and the file reads as the
// one rank 0 writes alone. docs/ARCHITECTURE.md ("Many machines") says why the folder is shared, not sent.
#include "gpkg_slices.h"

#include <groundplan/gis/tiled.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::output {

/// FIDs first..last (1-based, inclusive) that a rank holds of one layer.
struct FidRun {
  std::uint64_t first = 0, last = 0;
};

/// The FID runs of this rank's features in the one dataset: the plans (plan_number + 1) and the plan_members rows
/// (row_number + 1 on), merged where they follow each other. A rank's plans make at most two runs: its map's final
/// plans and its reduce's.
std::vector<FidRun> plan_runs(const gis::TiledResult& mine);
std::vector<FidRun> member_runs(const gis::TiledResult& mine);

struct RankGpkgWrite {
  std::string dst;                  // rank 0: the GeoPackage it writes (new); other ranks: unused
  std::string folder;               // rank 0: where every rank puts its slice (every rank sees it)
  bool nothing = false;             // rank 0: nothing to write (it has said why); every rank stops
  std::vector<std::string> flags;   // ogr2ogr options, no layer names (as for one process)
  std::vector<std::string> layers;  // the layers asked for: rank 0 writes them all, the others their
                                    // ground_plans and plan_members (the problems are rank 0's)
  bool progress = false;            // rank 0 reports the progress of its own slice
};

struct RankGpkgOutcome {
  bool ok = false;
  bool nothing = false;    // rank 0 had nothing to write
  int usage_error = 0;
  std::string why;         // rank 0: what failed, on which rank (the destination and every slice removed)
  double slice_s = 0;      // this rank: writing its slice
  double append_s = 0;     // rank 0: appending the slices
  std::size_t slices = 0;  // rank 0: slices appended
};

/// Collective over `ex`. `dataset` makes this rank's dataset (its plans: kept_by_each_rank; the callee closes it);
/// `translate` is the CLI's ogr2ogr; `after_slice` (a test hook, GROUNDPLAN_MPI_TEST_FAIL=R:throw@slice) runs
/// when this rank has written its slice. A write that fails or throws on any rank does not throw: every rank
/// learns it, every slice and the destination are removed, and rank 0's `why` names the ranks. MPI failures throw.
RankGpkgOutcome write_gpkg_from_every_rank(gis::TileExchange& ex, const RankGpkgWrite& w, const gis::TiledResult& mine,
                                           const std::function<GDALDatasetH()>& dataset, const Translate& translate,
                                           const std::function<void()>& after_slice);

}  // namespace groundplan::output

// SPDX-License-Identifier: MIT
#include "tiled_run.h"

#include "report.h"
#include "timing.h"
#include "write_output.h"

#include "open_options.h"
#ifdef GROUNDPLAN_WITH_MPI
#include "rank_runs.h"
#include "rank_writes.h"
#include "staged_output.h"
#endif

#include <groundplan/error.h>
#include <groundplan/gis/tiled.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include <unistd.h>

namespace groundplan::cli {
namespace {

using gis::PipelineOptions;

/// --tiles auto: the tiled run where one process would hold a large share of the machine's memory: when the
/// estimate of its footprints (estimated_footprint_bytes) passes a quarter of physical memory, in 2 or more
/// files. Not sooner: on an input that fits, the tiled run costs time (a 1.5 GB city in 16 tiles on 16 cores:
/// 3.8 s against 3.0 s, RESULTS.md) and writes the plans in another order (final ones first; a ring may start
/// at another vertex), where the one-process run is byte-identical whatever the threads or the cut.
bool tiles_pay_off(const std::vector<std::string>& inputs) {
  std::size_t files = 0;
  const std::uint64_t estimate = groundplan::gis::estimated_footprint_bytes(inputs, &files);
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  const std::uint64_t memory = pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : std::uint64_t{8} << 30;
  return files >= 2 && estimate > memory / 4;
}

/// Why the tiled run cannot give what was asked for (empty: it can).
std::string tiles_ruled_out(const PipelineOptions& options, const Ogr2ogrArgs& ogr, bool verify, bool preview) {
  if (options.detail.any()) return "a level of detail (--snap, --close-gaps, --simplify, --min-area ...) looks past a plan's own box";
  if (verify) return "--verify compares all footprints with all plans at once";
  if (preview) return "--preview draws all footprints at once";
  if (std::find(ogr.layers.begin(), ogr.layers.end(), std::string("footprints")) != ogr.layers.end())
    return "the footprints layer needs every footprint at once";
  return {};
}

}  // namespace

bool takes_tiled_run(const std::string& tiles, const PipelineOptions& options, const Ogr2ogrArgs& ogr, bool verify,
                     bool preview, int ranks) {
  // Tiles (issue 15): a large folder of tiles is mapped tile by tile with bounded memory (same plans).
  const std::string tiles_mode = lower(tiles);
  if (tiles_mode != "auto" && tiles_mode != "on" && tiles_mode != "off")
    throw groundplan::InvalidArgument("--tiles: '" + tiles + "' is not one of auto, on, off");
  const std::string no_tiles = tiles_ruled_out(options, ogr, verify, preview);
  if (tiles_mode == "on" && !no_tiles.empty())
    throw groundplan::InvalidArgument("--tiles on: " + no_tiles + "; use --tiles off");
  bool tiled = tiles_mode == "on";
  if (tiles_mode == "auto" && no_tiles.empty()) tiled = tiles_pay_off(options.inputs);
  if (ranks > 1) {  // mpirun -np N (N > 1): the ranks share the tiled run
    if (tiles_mode == "off" || !no_tiles.empty())
      throw groundplan::InvalidArgument("mpirun -np " + std::to_string(ranks) + ": the ranks share the "
                                        "tiled run, and " + (no_tiles.empty() ? std::string("--tiles off") : no_tiles) +
                                        "; run it without mpirun");
    tiled = true;
  }
  return tiled;
}

int run_tiled(const PipelineOptions& options, const Ogr2ogrArgs& ogr_in, const std::string& stats_path,
              const Progress& progress, Ranks* ranks) {
  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  std::shared_ptr<const groundplan::gis::TiledResult> result;
  Ogr2ogrArgs ogr = ogr_in;
#ifdef GROUNDPLAN_WITH_MPI
  // Over ranks (issue 15): the dataset is written into a staging folder that is moved into place once every rank
  // has finished (staged_output.h). A database: every rank writes its own plans (stage 5); a new GeoPackage: every
  // rank writes a slice (below); other files: rank 0 gets every plan and writes them all, the others only map and
  // reduce.
  std::unique_ptr<output::StagedOutput> staged;
  if (rank_count(ranks) > 1 && output::written_by_every_rank(ogr.format, ogr.dst))
    return run_tiled_into_database(options, ogr, stats_path, progress, *ranks);
  // A new GeoPackage: every rank writes its own plans into a slice, rank 0 joins them (gpkg_rank_slices.h), unless
  // an option spans features or the ranks do not share the destination's folder (--stats "writer" says why).
  std::string rank_0_writes;
  if (rank_count(ranks) > 1) {
    rank_0_writes = why_rank_0_writes(ogr, *ranks);
    if (rank_0_writes.empty()) return run_tiled_gpkg_by_ranks(options, ogr, stats_path, progress, *ranks);
    result = groundplan::gis::run_pipeline_tiled(options, *ranks, ranks->rank() == 0 ? progress : groundplan::Progress{});
    if (ranks->rank() != 0) {
      ranks->barrier();  // rank 0 has written
      return 0;
    }
    staged = std::make_unique<output::StagedOutput>(ogr.dst);
    ogr.dst = staged->path();
  }
  // Every rank waits for rank 0 here before the dataset is moved into place; rank 0's outcome is its return code.
  auto finish = [&](int rc) {
    if (rank_count(ranks) > 1) {
      ranks->barrier();
      if (rc == 0) staged->commit();
    }
    return rc;
  };
#else
  auto finish = [](int rc) { return rc; };
#endif
  if (!result) {
    // One process: the problems layer asked for is written even when no input can be read (over ranks the first
    // fault stops every rank).
    PipelineOptions own = options;
    own.unreadable_throws = !writes_problems(ogr);
    result = groundplan::gis::run_pipeline_tiled(own, progress);
  }
  const groundplan::gis::TiledResult& r = *result;
  auto stats = [&](double write_s, double index_s, const WriteOutcome* written) {
    return write_tiled_stats(stats_path, r, r.plan_count(), write_s, index_s, written, seconds_since(t0),
                             groundplan::gis::process_cpu_seconds() - cpu0);
  };
  const std::string ds_name = std::string(groundplan::driver::kPrefix) + ogr.src;
  const std::size_t id_chars = writes_dbf(ogr) ? 254 : 0;
  if (r.footprints == 0) {
    // Over ranks the output is staged and not committed on failure: nothing is written there.
    say_nothing_usable(ogr, r.buildings_read, r.problems,
                       rank_count(ranks) > 1
                           ? nullptr
                           : new groundplan::driver::OGRGroundPlanDataSource(ds_name, result, id_chars, options.threads));
    stats(0, 0, nullptr);
    return finish(1);
  }
  auto* ds = new groundplan::driver::OGRGroundPlanDataSource(ds_name, result, id_chars, options.threads);
  // Plans are read back from the run's spill by position: datasets side by side may read it at once.
  WriteOutcome w = write_output(ds, ogr, options.threads, [&](int threads) {
    return new groundplan::driver::OGRGroundPlanDataSource(ds_name, result, id_chars, threads);
  });
#ifdef GROUNDPLAN_WITH_MPI
  if (rank_count(ranks) > 1) w.writer["rank_0_writes_every_plan"] = rank_0_writes;
#endif
  if (!w.ok) {
    std::fprintf(stderr, "groundplan: could not write %s%s\n", ogr_in.dst.c_str(),
                 w.usage_error ? " (bad ogr2ogr options)" : "");
    return finish(1);
  }
  if (!w.members_note.empty()) std::fprintf(stderr, "groundplan: note: %s\n", w.members_note.c_str());
  // Over ranks the dataset is in place only now: "wrote" is said after that.
  const int rc = finish(stats(w.write_s, w.index_s, &w) ? 0 : 1);
  if (!ogr.quiet) print_tiled_summary(r, ogr, ogr_in.dst, r.plan_count(), seconds_since(t0), w.write_s);
  return rc;
}

}  // namespace groundplan::cli

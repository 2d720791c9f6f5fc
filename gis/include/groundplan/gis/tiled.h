// SPDX-License-Identifier: MIT
#pragma once
// Country scale on one machine (issue 15): the inputs as tiles (one input file each), map/reduce with bounded
// memory. Map: a tile's footprints -> its plans (the same engine as run_pipeline). A plan whose bounding box
// meets no other tile's extent is final; the others ("seam" plans) are united again at the end, from their
// member footprints, with the same engine. docs/ARCHITECTURE.md ("Tiles") says why this is the one-process
// union exactly.
#include <groundplan/gis/pipeline.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace groundplan::gis {

/// One plan as the output layers need it: the polygon, its members' global footprint indices (the index
/// run_pipeline would give them: footprints counted in file order), their source ids and height range.
struct StoredPlan {
  GroundPlan plan;                      // members: global footprint indices, ascending
  std::vector<std::string> member_ids;  // source_id of each member, same order
  std::vector<std::string> member_buildings;  // the Building of each member (building_id_of), same order
  double min_z = 0, max_z = 0;          // over the members
};

/// How the ranks of a tiled run talk (issue 15 stage 2). One process is one rank (LocalExchange, never
/// sending); `mpirun -np N groundplan` gives N (driver/cli/mpi_exchange.h). Every call but send/receive is
/// collective: every rank makes it, in the same order. Any failure throws (an MPI build aborts the job).
class TileExchange {
 public:
  virtual ~TileExchange() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Every rank's `mine`, concatenated in rank order, on every rank; `sizes` (optional) gets each part's size.
  virtual std::vector<char> allgather(const std::vector<char>& mine, std::vector<std::uint64_t>* sizes = nullptr) = 0;
  /// Point to point, blocking; messages from one rank to another arrive in the order sent.
  virtual void send(int to, const std::vector<char>& bytes) = 0;
  virtual std::vector<char> receive(int from) = 0;
  /// Progress over ranks (not collective; the calling thread is the one making the collective calls). A rank
  /// r > 0 tells rank 0 how many bytes of its tiles it has read so far, `last` once it has read them all; it does
  /// not wait for rank 0 to hear it. By default (one process) nothing is said.
  virtual void tell_progress(std::uint64_t bytes_read, bool last) {
    (void)bytes_read;
    (void)last;
  }
  /// Rank 0: gives `more` the bytes the other ranks have said they read since the last word it heard, word by word
  /// as they come (those arrived so far; with `until_last`, until every other rank's last word has come).
  virtual void heard_progress(bool until_last, const std::function<void(std::uint64_t)>& more) {
    (void)until_last;
    (void)more;
  }
};

/// The exchange of a run in one process: rank 0 of 1.
class LocalExchange final : public TileExchange {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  std::vector<char> allgather(const std::vector<char>& mine, std::vector<std::uint64_t>* sizes = nullptr) override;
  void send(int to, const std::vector<char>& bytes) override;
  std::vector<char> receive(int from) override;
};

/// One rank's share of a run over ranks (--stats "mpi").
struct RankStats {
  std::size_t tiles = 0;            // input files it mapped
  std::uint64_t bytes = 0;          // their bytes
  std::size_t footprints = 0;       // footprints it made
  std::size_t seam_footprints = 0;  // footprints it united in the reduce (its own and those received)
  double map_s = 0, reduce_s = 0, gather_s = 0;  // wall: map; tree reduce; finals streamed to rank 0
  double cpu_s = 0;
  std::uint64_t peak_rss_bytes = 0;  // at the end of its part (rank 0: before writing)
};

/// What the tiled run did (--stats "tiles").
struct TileStats {
  std::size_t tiles = 0;                // input files mapped one at a time (a tile each)
  std::size_t tile_plans = 0;           // plans the tiles' unions gave
  std::size_t final_plans = 0;          // of those, final at once (box meets no other tile's extent)
  std::size_t seam_plans = 0;           // of those, seams: united again at the end
  std::size_t seam_footprints = 0;      // the seams' member footprints, kept for the reduce
  std::size_t reduced_plans = 0;        // plans the reduce gave from the seams
  std::size_t max_tile_footprints = 0;  // the largest tile, in footprints
  std::size_t tiles_in_flight = 0;      // tiles read side by side at most (their footprints are in memory)
  std::uint64_t spill_bytes = 0;        // the map's temporary file (plans + their member footprints)
  double map_s = 0, reduce_s = 0;       // wall times: read + tile unions + spill; seams' union
  std::size_t reduce_rounds = 0;        // the reduce tree's rounds after each rank's own: ceil(log2(ranks))
  std::uint64_t progress_bytes_heard = 0;  // rank 0: bytes the other ranks said they read (tell_progress)
};

/// The result of a tiled run. The plans live in a temporary file (deleted when this is destroyed) and
/// are read back one at a time; nothing grows with the input in memory but an 8-byte offset a final plan,
/// the problems, and the seams.
class TiledResult {
 public:
  virtual ~TiledResult() = default;
  /// Final plans first (tile by tile in file order, each tile's in the engine's order), then the plans
  /// the reduce made from the seams: a deterministic order whatever the threads.
  virtual std::size_t plan_count() const = 0;
  /// Plan i (0-based); safe to call from several threads at once. Throws Error when the temporary file
  /// cannot be read back.
  virtual StoredPlan plan(std::size_t i) const = 0;
  /// Rows of plan_members before plan i (the members of plans 0..i-1); i = plan_count() gives all rows.
  virtual std::uint64_t members_before(std::size_t i) const = 0;
  /// The number (0-based) plan i has in the one dataset: i, except where every rank writes its own plans
  /// (FinalPlans::kept_by_each_rank): then the index it would have in rank 0's gathered order, so that gp_id and
  /// feature ids are those of a run that gathers (the map's final plans rank by rank, then the reduce's).
  virtual std::uint64_t plan_number(std::size_t i) const { return i; }
  /// The plan_members row (0-based) of plan i's first member in the one dataset (members_before(i) where
  /// plan_number(i) is i).
  virtual std::uint64_t row_number(std::size_t i) const { return members_before(i); }

  std::vector<Problem> problems;
  std::size_t footprints = 0;  // footprints made (all tiles), as PipelineResult::footprints.size()
  std::size_t buildings_read = 0, buildings_dropped = 0, blocks = 0;
  std::string raster_backend, crs_wkt, crs_name;
  StageTimings timings;
  ReadStats reading;
  TileStats tiles;
  std::vector<RankStats> ranks;     // rank 0 of a run over ranks: every rank's share, in rank order
  double extent[4] = {0, 0, 0, 0};  // xmin, ymin, xmax, ymax of all footprints (working CRS)
};

/// What one process would hold for the inputs' footprints, estimated from the files' sizes without reading
/// them: one process keeps every footprint (about 870 B a building, tests/bench/RESULTS.md "Tiles"), which is
/// some 12 % of the bytes of LoD1 CityGML (less for LoD2, CityJSON, KML), but several times the bytes of a 2D
/// OGR layer of footprints. Factors: city model files 0.15, other (OGR) files 5. `files`: how many files the
/// inputs name (a folder: its input files; a zip: its entries). For --tiles auto. Throws InputError as
/// run_pipeline does.
std::uint64_t estimated_footprint_bytes(const std::vector<std::string>& inputs, std::size_t* files = nullptr);

/// Runs the pipeline tile by tile (a tile = one input file). Same plans, members, problems and counts as
/// run_pipeline (as sets; the order is the one TiledResult states). A level of detail is refused
/// (InvalidArgument): closing gaps and simplifying look past a plan's own box. Throws as run_pipeline.
std::unique_ptr<TiledResult> run_pipeline_tiled(const PipelineOptions& options, const Progress& progress = {});

/// Where the final plans of a run over ranks end up.
enum class FinalPlans {
  to_rank_0,          // streamed to rank 0, which writes the one dataset (files)
  kept_by_each_rank,  // each rank keeps its own, numbered as rank 0 would have them, and writes them (a database)
};

/// The same run spread over the ranks of `exchange` (issue 15 stage 2): rank r maps a contiguous run of the
/// input files (balanced by bytes), the tiles' extents are exchanged, each rank classifies its plans as the
/// one-process tiled run does, the seams are reduced by a tree (rank pairs, ceil(log2 N) rounds) with the same
/// engine, and every final plan is streamed to rank 0. Rank 0's result holds all plans, problems and counts;
/// the other ranks' results hold none (plan_count() 0). With FinalPlans::kept_by_each_rank (stage 5) nothing is
/// streamed: every rank's result holds its own final plans (plan_number/row_number give their place in the one
/// dataset, member ids are global), rank 0's also the problems and the counts of all ranks. Collective: every
/// rank calls it.
std::unique_ptr<TiledResult> run_pipeline_tiled(const PipelineOptions& options, TileExchange& exchange,
                                                const Progress& progress = {},
                                                FinalPlans final_plans = FinalPlans::to_rank_0);

}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
#pragma once
// Country scale on one machine (issue 15): the inputs as tiles (one input file each), map/reduce with bounded
// memory. Map: a tile's footprints -> its plans (the same engine as run_pipeline). A plan whose bounding box
// meets no other tile's extent is final; the others ("seam" plans) are united again at the end, from their
// member footprints, with the same engine. docs/ARCHITECTURE.md ("Tiles") says why this is the one-process
// union exactly.
#include <groundplan/gis/pipeline.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace groundplan::gis {

/// One plan as the output layers need it: the polygon, its members' global footprint indices (the index
/// run_pipeline would give them: footprints counted in file order), their source ids and height range.
struct StoredPlan {
  GroundPlan plan;                      // members: global footprint indices, ascending
  std::vector<std::string> member_ids;  // source_id of each member, same order
  double min_z = 0, max_z = 0;          // over the members
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

  std::vector<Problem> problems;
  std::size_t footprints = 0;  // footprints made (all tiles), as PipelineResult::footprints.size()
  std::size_t buildings_read = 0, buildings_dropped = 0, blocks = 0;
  std::string raster_backend, crs_wkt, crs_name;
  StageTimings timings;
  ReadStats reading;
  TileStats tiles;
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

}  // namespace groundplan::gis

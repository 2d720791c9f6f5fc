// SPDX-License-Identifier: MIT
// run_pipeline_tiled (issue 15): read -> footprints -> union one tile (input file) at a time, the tile's plans
// and their member footprints to a temporary file; once every tile's extent is known, the plans whose box meets
// no other tile's extent are final, the seams' footprints are united again. docs/ARCHITECTURE.md ("Tiles").
#include <groundplan/error.h>
#include <groundplan/gis/reader.h>
#include <groundplan/gis/tiled.h>
#include <groundplan/ground_plans.h>

#include "pipeline/file_reading.h"
#include "pipeline/inputs.h"
#include "pipeline/plan_spill.h"
#include "pipeline/tile_extents.h"

#include <cpl_vsi.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>

namespace groundplan::gis {
namespace {

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t0) { return std::chrono::duration<double>(clock_type::now() - t0).count(); }

class SpilledResult final : public TiledResult {
 public:
  std::size_t plan_count() const override { return finals.size() + reduced.size(); }
  StoredPlan plan(std::size_t i) const override {
    if (i >= finals.size()) return reduced.at(i - finals.size());
    detail::SpilledPlan s = spill.read(finals[i], false);
    StoredPlan out;
    out.plan = std::move(s.plan);
    out.member_ids.reserve(s.footprints.size());
    for (std::size_t k = 0; k < s.footprints.size(); ++k) {
      const Footprint& fp = s.footprints[k];
      out.min_z = k ? std::min(out.min_z, fp.min_z) : fp.min_z;
      out.max_z = k ? std::max(out.max_z, fp.max_z) : fp.max_z;
      out.member_ids.push_back(fp.source_id);
    }
    return out;
  }

  std::uint64_t members_before(std::size_t i) const override { return rows_before.at(i); }

  detail::PlanSpill spill;
  std::vector<std::uint64_t> rows_before{0};  // plan_members rows before each plan, and all of them last
  std::vector<std::uint64_t> finals;  // offsets of the final plans in the spill, in tile order
  std::vector<StoredPlan> reduced;    // the plans the reduce made from the seams
};

detail::Box box_of(const Ring& r) {
  detail::Box b = detail::empty_box();
  for (const Point2& p : r) detail::grow(b, p.x, p.y);
  return b;
}

/// The reduce: the seam footprints (in global order, as one process would hold them) united by the same engine;
/// members mapped back to global indices.
std::vector<StoredPlan> reduce_seams(std::vector<Footprint>& fps, std::vector<std::uint32_t>& ids,
                                     const UnionParams& params, std::vector<Problem>& problems, UnionStats& stats) {
  std::vector<std::size_t> order(fps.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return ids[a] < ids[b]; });
  std::vector<Footprint> sorted(fps.size());
  std::vector<std::uint32_t> sorted_ids(fps.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    sorted[k] = std::move(fps[order[k]]);
    sorted_ids[k] = ids[order[k]];
  }
  fps.clear();
  ids.clear();
  UnionParams p = params;
  p.stats = &stats;
  std::vector<GroundPlan> plans = build_ground_plans(sorted, p, problems);
  std::vector<StoredPlan> out(plans.size());
  for (std::size_t i = 0; i < plans.size(); ++i) {
    StoredPlan& s = out[i];
    s.plan = std::move(plans[i]);
    for (std::size_t k = 0; k < s.plan.members.size(); ++k) {
      const Footprint& fp = sorted[s.plan.members[k]];
      s.min_z = k ? std::min(s.min_z, fp.min_z) : fp.min_z;
      s.max_z = k ? std::max(s.max_z, fp.max_z) : fp.max_z;
      s.member_ids.push_back(fp.source_id);
      s.plan.members[k] = sorted_ids[s.plan.members[k]];
    }
  }
  return out;
}

std::unique_ptr<TiledResult> run_tiled(const PipelineOptions& options, const Progress& progress, std::size_t threads) {
  const double cpu0 = process_cpu_seconds();
  auto out = std::make_unique<SpilledResult>();
  PipelineResult acc;  // what merge_file adds to: counts, problems, CRS; its footprints are one tile's
  const std::vector<std::string> files = detail::expand_inputs(options.inputs, acc.problems);
  acc.reading.files = files.size();
  acc.reading.threads = threads;
  acc.reading.bytes = detail::total_bytes(files);
  TileStats& ts = out->tiles;
  ts.tiles = files.size();

  detail::ReadContext context;
  context.working_definition = options.t_srs;
  std::size_t files_failed = 0;
  std::string first_failure;
  detail::ByteProgress bytes(progress.sub(0, 0.9), acc.reading.bytes);
  progress.report(0, "reading tiles");
  std::vector<detail::Box> extents;
  detail::Box all = detail::empty_box();
  std::uint64_t next_global = 0;
  UnionParams union_params = options.union_params;
  const auto t_map = clock_type::now();
  double union_wall = 0;

  // Map one tile: its footprints (in acc after merge_file) -> plans -> the spill, with member footprints.
  auto map_tile = [&](detail::FileRead&& r, std::size_t f) {
    detail::merge_file(std::move(r), files[f], context, acc, files_failed, first_failure);
    std::vector<Footprint> fps = std::move(acc.footprints);
    acc.footprints.clear();
    const auto tile = static_cast<std::uint32_t>(extents.size());
    detail::Box extent = detail::empty_box();
    for (const Footprint& fp : fps)
      for (const Polygon& p : fp.polygons) {
        for (const Point2& q : p.outer) detail::grow(extent, q.x, q.y);
        for (const Ring& h : p.holes)
          for (const Point2& q : h) detail::grow(extent, q.x, q.y);
      }
    extents.push_back(extent);
    if (extent[0] <= extent[2]) {
      detail::grow(all, extent[0], extent[1]);
      detail::grow(all, extent[2], extent[3]);
    }
    ts.max_tile_footprints = std::max(ts.max_tile_footprints, fps.size());
    if (next_global + fps.size() > std::numeric_limits<std::uint32_t>::max())
      throw InputError("tiled run: more than 2^32 footprints");
    if (fps.empty()) return;
    const auto t_union = clock_type::now();
    UnionStats us;
    union_params.stats = &us;
    std::vector<GroundPlan> plans = build_ground_plans(fps, union_params, acc.problems);
    acc.blocks += us.blocks;
    acc.raster_backend = us.backend;
    acc.timings.blocks_s += us.blocks_s;
    std::vector<const Footprint*> members;
    for (GroundPlan& gp : plans) {
      members.clear();
      for (std::uint32_t& m : gp.members) {
        members.push_back(&fps[m]);
        m = static_cast<std::uint32_t>(next_global + m);
      }
      out->spill.append(gp, members, tile, box_of(gp.polygon.outer));
    }
    ts.tile_plans += plans.size();
    next_global += fps.size();
    union_wall += seconds_since(t_union);
  };

  // Until the working CRS is known the files are read one by one (the first georeferenced one decides it);
  // then in groups of one a thread, side by side, and mapped in file order: at most `threads` tiles'
  // footprints are in memory at once.
  std::size_t fi = 0;
  for (; fi < files.size() && context.working_definition.empty(); ++fi) {
    map_tile(detail::read_file(files[fi], options, context, threads, 0, bytes), fi);
    ts.tiles_in_flight = std::max<std::size_t>(ts.tiles_in_flight, 1);
  }
  while (fi < files.size()) {
    const std::size_t n = std::min(threads, files.size() - fi);
    std::uint64_t shared = 0;
    for (std::size_t k = 0; k < n; ++k) {
      VSIStatBufL st;
      if (VSIStatL(files[fi + k].c_str(), &st) == 0) shared += static_cast<std::uint64_t>(st.st_size);
    }
    std::vector<detail::FileRead> reads(n);
    const detail::ReadContext fixed = context;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k)
        reads[k] = detail::read_file(files[fi + k], options, fixed, threads, shared, bytes);
    }, tbb::simple_partitioner());
    for (std::size_t k = 0; k < n; ++k) map_tile(std::move(reads[k]), fi + k);
    ts.tiles_in_flight = std::max(ts.tiles_in_flight, n);
    fi += n;
  }
  if (files_failed == files.size() && next_global == 0) throw InputError(first_failure);
  out->spill.flush();
  ts.spill_bytes = out->spill.size();
  ts.map_s = seconds_since(t_map);

  // Reduce: every extent is known now.
  progress.report(0.9, "seams");
  const auto t_reduce = clock_type::now();
  const detail::TileExtents index(std::move(extents));
  std::vector<Footprint> seam_fps;
  std::vector<std::uint32_t> seam_ids;
  for (std::uint64_t at = 0; at < out->spill.size();) {
    const std::uint64_t here = at;
    detail::SpilledPlan s = out->spill.read(at, true, &at);
    if (!index.meets_other(s.box, s.tile)) {
      out->finals.push_back(here);
      out->rows_before.push_back(out->rows_before.back() + s.ids.size());
      continue;
    }
    ++ts.seam_plans;
    for (std::size_t k = 0; k < s.ids.size(); ++k) {
      seam_fps.push_back(std::move(s.footprints[k]));
      seam_ids.push_back(s.ids[k]);
    }
  }
  ts.final_plans = out->finals.size();
  ts.seam_footprints = seam_fps.size();
  if (!seam_fps.empty()) {
    UnionStats us;
    out->reduced = reduce_seams(seam_fps, seam_ids, options.union_params, acc.problems, us);
    acc.blocks += us.blocks;
    acc.timings.blocks_s += us.blocks_s;
  }
  for (const StoredPlan& p : out->reduced) out->rows_before.push_back(out->rows_before.back() + p.plan.members.size());
  ts.reduced_plans = out->reduced.size();
  ts.reduce_s = seconds_since(t_reduce);

  out->problems = std::move(acc.problems);
  out->footprints = static_cast<std::size_t>(next_global);
  out->buildings_read = acc.buildings_read;
  out->buildings_dropped = acc.buildings_dropped;
  out->blocks = acc.blocks;
  out->raster_backend = acc.raster_backend;
  out->crs_wkt = acc.crs_wkt;
  out->crs_name = acc.crs_name;
  out->reading = acc.reading;
  out->timings = acc.timings;
  out->timings.read_s = std::max(0.0, ts.map_s - union_wall - acc.timings.footprints_s);
  out->timings.union_s = union_wall - acc.timings.blocks_s + ts.reduce_s;
  out->timings.cpu_s = process_cpu_seconds() - cpu0;
  std::copy(all.begin(), all.end(), out->extent);
  progress.report(1.0, "done");
  return out;
}

}  // namespace

std::uint64_t estimated_footprint_bytes(const std::vector<std::string>& inputs, std::size_t* files) {
  std::vector<Problem> ignored;
  const std::vector<std::string> list = detail::expand_inputs(inputs, ignored);
  if (files) *files = list.size();
  double estimate = 0;
  for (const std::string& f : list)
    estimate += static_cast<double>(detail::total_bytes({f})) * (is_input_name(f) ? 0.15 : 5.0);
  return static_cast<std::uint64_t>(estimate);
}

std::unique_ptr<TiledResult> run_pipeline_tiled(const PipelineOptions& options, const Progress& progress) {
  if (options.threads < 0) throw InvalidArgument("threads: " + std::to_string(options.threads) + " is not >= 1 (0 = all cores)");
  if (options.detail.any())
    throw InvalidArgument("tiles: a level of detail (--snap, --close-gaps, --simplify, --min-area, --preset ...) "
                          "looks past a plan's own box; use --tiles off");
  const std::size_t threads = thread_count(options.threads);
  tbb::task_arena arena(static_cast<int>(threads));
  std::unique_ptr<TiledResult> result;
  arena.execute([&] { result = run_tiled(options, progress, threads); });
  return result;
}

}  // namespace groundplan::gis

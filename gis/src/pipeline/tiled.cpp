// SPDX-License-Identifier: MIT
// run_pipeline_tiled (issue 15): read -> footprints -> union one tile (input file) at a time, the tile's plans
// and their member footprints to a temporary file; once every tile's extent is known, the plans whose box meets
// no other tile's extent are final, the seams' footprints are united again. Over MPI ranks (TileExchange) each rank
// maps a run of the tiles and the seams are reduced by a tree of rank pairs. docs/ARCHITECTURE.md ("Tiles").
#include <groundplan/error.h>
#include <groundplan/gis/reader.h>
#include <groundplan/gis/tiled.h>
#include <groundplan/ground_plans.h>

#include "pipeline/file_reading.h"
#include "pipeline/inputs.h"
#include "pipeline/plan_spill.h"
#include "pipeline/tile_extents.h"
#include "pipeline/tile_ranks.h"

#include <cpl_vsi.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <sys/resource.h>

namespace groundplan::gis {
namespace {

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t0) { return std::chrono::duration<double>(clock_type::now() - t0).count(); }

class SpilledResult final : public TiledResult {
 public:
  std::size_t plan_count() const override { return finals.size(); }
  StoredPlan plan(std::size_t i) const override {
    detail::SpilledPlan s = spill.read(finals.at(i), false);
    StoredPlan out;
    out.plan = std::move(s.plan);
    if (!segments.empty())
      for (std::uint32_t& m : out.plan.members) m += segment(i).id_shift;
    out.member_ids.reserve(s.footprints.size());
    out.member_buildings.reserve(s.footprints.size());
    for (std::size_t k = 0; k < s.footprints.size(); ++k) {
      const Footprint& fp = s.footprints[k];
      out.min_z = k ? std::min(out.min_z, fp.min_z) : fp.min_z;
      out.max_z = k ? std::max(out.max_z, fp.max_z) : fp.max_z;
      out.member_buildings.push_back(building_id_of(fp));
      out.member_ids.push_back(fp.source_id);
    }
    return out;
  }

  std::uint64_t members_before(std::size_t i) const override { return rows_before.at(i); }
  std::uint64_t plan_number(std::size_t i) const override {
    if (segments.empty()) return i;
    const Segment& g = segment(i);
    return g.plan + (i - g.first);
  }
  std::uint64_t row_number(std::size_t i) const override {
    if (segments.empty()) return rows_before.at(i);
    const Segment& g = segment(i);
    return g.row + (rows_before.at(i) - rows_before.at(g.first));
  }

  /// A rank that keeps its final plans (FinalPlans::kept_by_each_rank): its plans from `first` on are numbered
  /// from `plan` in the one dataset, their members from row `row`, member ids shifted by `id_shift` to global
  /// ones (the map's plans hold the rank's own footprint numbers). Ascending `first`; empty: numbered as stored.
  struct Segment {
    std::size_t first = 0;
    std::uint64_t plan = 0, row = 0;
    std::uint32_t id_shift = 0;
  };
  std::vector<Segment> segments;
  const Segment& segment(std::size_t i) const {
    auto it = std::upper_bound(segments.begin(), segments.end(), i,
                               [](std::size_t v, const Segment& g) { return v < g.first; });
    return *(it - 1);
  }

  detail::PlanSpill spill;
  std::vector<std::uint64_t> rows_before{0};  // plan_members rows before each plan, and all of them last
  std::vector<std::uint64_t> finals;  // offsets in the spill: the map's final plans in tile order, then the reduce's

  void add_final(std::uint64_t offset, std::size_t members) {
    finals.push_back(offset);
    rows_before.push_back(rows_before.back() + members);
  }
};

/// Final plans of one rank: offsets in its spill and member counts.
struct Finals {
  std::vector<std::uint64_t> offsets;
  std::vector<std::size_t> members;
  void add(std::uint64_t offset, std::size_t n) {
    offsets.push_back(offset);
    members.push_back(n);
  }
};

detail::Box box_of(const Ring& r) {
  detail::Box b = detail::empty_box();
  for (const Point2& p : r) detail::grow(b, p.x, p.y);
  return b;
}

std::uint64_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::uint64_t>(u.ru_maxrss) * 1024;
}

std::vector<const Footprint*> pointers(const std::vector<Footprint>& fps) {
  std::vector<const Footprint*> out;
  out.reserve(fps.size());
  for (const Footprint& fp : fps) out.push_back(&fp);
  return out;
}

/// A reduce step: the footprints of `seams` (in global order, as one process would hold them) united by the
/// same engine; each plan comes back with its members (global indices) and their footprints, box set.
std::vector<detail::SpilledPlan> unite_seams(std::vector<detail::SpilledPlan>&& seams, const UnionParams& params,
                                             std::vector<Problem>& problems, UnionStats& stats) {
  std::vector<Footprint> fps;
  std::vector<std::uint32_t> ids;
  for (detail::SpilledPlan& s : seams)
    for (std::size_t k = 0; k < s.ids.size(); ++k) {
      fps.push_back(std::move(s.footprints[k]));
      ids.push_back(s.ids[k]);
    }
  seams.clear();
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
  std::vector<detail::SpilledPlan> out(plans.size());
  for (std::size_t i = 0; i < plans.size(); ++i) {
    detail::SpilledPlan& s = out[i];
    s.plan = std::move(plans[i]);
    for (std::uint32_t& m : s.plan.members) {
      s.footprints.push_back(sorted[m]);
      m = sorted_ids[m];
    }
    s.ids = s.plan.members;
    s.box = box_of(s.plan.polygon.outer);
  }
  return out;
}

/// What a rank adds to rank 0's result besides plans: counts, problems, its share (RankStats).
struct RankPart {
  PipelineResult* acc = nullptr;
  TileStats* tiles = nullptr;
  RankStats* share = nullptr;
  std::uint64_t files_failed = 0;
};

void pack_part(const RankPart& part, detail::Packer& p) {
  const PipelineResult& a = *part.acc;
  const TileStats& t = *part.tiles;
  const RankStats& r = *part.share;
  for (std::uint64_t v : {std::uint64_t(a.buildings_read), std::uint64_t(a.buildings_dropped), std::uint64_t(a.blocks),
                          std::uint64_t(a.reading.files_chunked), std::uint64_t(a.reading.chunks), part.files_failed,
                          std::uint64_t(t.tile_plans), std::uint64_t(t.final_plans), std::uint64_t(t.seam_plans),
                          std::uint64_t(t.seam_footprints), std::uint64_t(t.reduced_plans),
                          std::uint64_t(t.max_tile_footprints), std::uint64_t(t.tiles_in_flight), t.spill_bytes,
                          std::uint64_t(r.tiles), r.bytes, std::uint64_t(r.footprints), std::uint64_t(r.seam_footprints),
                          r.peak_rss_bytes})
    p.put(v);
  for (double v : {a.timings.footprints_s, a.timings.blocks_s, r.map_s, r.reduce_s, r.gather_s, r.cpu_s}) p.put(v);
  p.str(a.raster_backend);
  p.problems(a.problems);
}

/// Adds a packed part to rank 0's totals (counts summed, largest tile and tiles in flight the maximum).
void add_part(detail::Unpacker& u, PipelineResult& a, TileStats& t, std::vector<RankStats>& shares,
              std::uint64_t& files_failed) {
  auto g = [&] { return u.get<std::uint64_t>(); };
  a.buildings_read += g();
  a.buildings_dropped += g();
  a.blocks += g();
  a.reading.files_chunked += g();
  a.reading.chunks += g();
  files_failed += g();
  t.tile_plans += g();
  t.final_plans += g();
  t.seam_plans += g();
  t.seam_footprints += g();
  t.reduced_plans += g();
  t.max_tile_footprints = std::max<std::size_t>(t.max_tile_footprints, g());
  t.tiles_in_flight = std::max<std::size_t>(t.tiles_in_flight, g());
  t.spill_bytes += g();
  RankStats r;
  r.tiles = g();
  r.bytes = g();
  r.footprints = g();
  r.seam_footprints = g();
  r.peak_rss_bytes = g();
  a.timings.footprints_s += u.get<double>();
  a.timings.blocks_s += u.get<double>();
  r.map_s = u.get<double>();
  r.reduce_s = u.get<double>();
  r.gather_s = u.get<double>();
  r.cpu_s = u.get<double>();
  t.map_s = std::max(t.map_s, r.map_s);
  t.reduce_s = std::max(t.reduce_s, r.reduce_s + r.gather_s);
  const std::string backend = u.str();
  if (a.raster_backend.empty()) a.raster_backend = backend;
  u.problems(a.problems);
  shares.push_back(r);
}

constexpr std::size_t kStreamBytes = 4u << 20;

/// Rank r > 0: its final plans (spill offsets), ids shifted by `id_offset` to global ones, to rank 0 in
/// messages of about kStreamBytes; an empty message ends the stream.
void stream_finals(const detail::PlanSpill& spill, const Finals& finals, std::uint32_t id_offset, TileExchange& ex) {
  std::vector<char> buffer;
  for (std::uint64_t at : finals.offsets) {
    detail::SpilledPlan s = spill.read(at, false);
    for (std::uint32_t& m : s.plan.members) m += id_offset;
    detail::PlanSpill::encode(s.plan, pointers(s.footprints), s.tile, s.box, buffer);
    if (buffer.size() >= kStreamBytes) {
      ex.send(0, buffer);
      buffer.clear();
    }
  }
  if (!buffer.empty()) ex.send(0, buffer);
  ex.send(0, {});
}

/// Rank 0: one rank's stream of final plans, appended to the spill as they come.
void receive_finals(int from, SpilledResult& out, TileExchange& ex) {
  for (;;) {
    const std::vector<char> bytes = ex.receive(from);
    if (bytes.empty()) return;
    const std::vector<detail::SpilledPlan> plans = detail::PlanSpill::decode_all(bytes, false);
    std::size_t at = 0;
    for (const detail::SpilledPlan& s : plans) {
      const std::size_t n = detail::PlanSpill::record_length(bytes.data() + at, bytes.size() - at);
      out.add_final(out.spill.append_encoded(bytes.data() + at, n), s.ids.size());
      at += n;
    }
  }
}

/// FinalPlans::kept_by_each_rank: where this rank's final plans stand in the order rank 0 would have gathered
/// them (every rank's map plans in rank order, then every rank's reduce plans), from one allgather of the counts.
void number_kept_plans(const Finals& map_finals, const Finals& reduce_finals, std::uint32_t id_offset,
                       SpilledResult& out, TileExchange& ex) {
  auto rows = [](const Finals& f) { return std::accumulate(f.members.begin(), f.members.end(), std::uint64_t{0}); };
  detail::Packer p;
  for (std::uint64_t v : {std::uint64_t(map_finals.offsets.size()), rows(map_finals),
                          std::uint64_t(reduce_finals.offsets.size()), rows(reduce_finals)})
    p.put(v);
  const std::vector<char> all = ex.allgather(p.bytes);
  if (all.size() != p.bytes.size() * static_cast<std::size_t>(ex.size()))
    throw Error("tiled run over ranks: plan counts of the wrong size");
  std::uint64_t map_plans = 0, map_rows = 0, reduce_plans = 0, reduce_rows = 0;  // before this rank
  std::uint64_t all_map_plans = 0, all_map_rows = 0;
  detail::Unpacker u(all.data(), all.size());
  for (int r = 0; r < ex.size(); ++r) {
    const std::uint64_t mp = u.get<std::uint64_t>(), mr = u.get<std::uint64_t>();
    const std::uint64_t rp = u.get<std::uint64_t>(), rr = u.get<std::uint64_t>();
    if (r < ex.rank()) {
      map_plans += mp;
      map_rows += mr;
      reduce_plans += rp;
      reduce_rows += rr;
    }
    all_map_plans += mp;
    all_map_rows += mr;
  }
  for (std::size_t i = 0; i < map_finals.offsets.size(); ++i) out.add_final(map_finals.offsets[i], map_finals.members[i]);
  for (std::size_t i = 0; i < reduce_finals.offsets.size(); ++i)
    out.add_final(reduce_finals.offsets[i], reduce_finals.members[i]);
  out.segments = {{0, map_plans, map_rows, id_offset},
                  {map_finals.offsets.size(), all_map_plans + reduce_plans, all_map_rows + reduce_rows, 0}};
}

std::unique_ptr<TiledResult> run_tiled(const PipelineOptions& options, const Progress& progress, std::size_t threads,
                                       TileExchange& ex, FinalPlans final_plans) {
  const double cpu0 = process_cpu_seconds();
  const int me = ex.rank(), ranks = ex.size();
  auto out = std::make_unique<SpilledResult>();
  PipelineResult acc;  // what merge_file adds to: counts, problems, CRS; its footprints are one tile's
  std::vector<Problem> input_problems;
  const std::vector<std::string> files = detail::expand_inputs(options.inputs, input_problems);
  if (me == 0) acc.problems = std::move(input_problems);
  std::vector<std::uint64_t> sizes(files.size(), 0);
  for (std::size_t f = 0; f < files.size(); ++f) sizes[f] = detail::total_bytes({files[f]});
  acc.reading.files = files.size();
  acc.reading.threads = threads;
  acc.reading.bytes = std::accumulate(sizes.begin(), sizes.end(), std::uint64_t{0});
  TileStats& ts = out->tiles;
  ts.tiles = files.size();
  RankStats share;

  detail::ReadContext context;
  context.working_definition = options.t_srs;
  std::size_t files_failed = 0;
  std::string first_failure;
  // Over ranks, rank 0's count also takes in the bytes the other ranks say they read (TileExchange::tell_progress).
  detail::ByteProgress bytes(progress.sub(0, 0.9), acc.reading.bytes);
  progress.report(0, "reading tiles");
  std::vector<detail::Box> extents;  // this rank's tiles, in file order
  std::size_t tile_first = 0;        // the global index of this rank's first tile
  std::uint64_t next_local = 0;      // footprints made on this rank (their global index: the rank's offset + this)
  UnionParams union_params = options.union_params;
  const auto t_map = clock_type::now();
  double union_wall = 0;

  // Map one tile: its footprints (in acc after merge_file) -> plans -> the spill, with member footprints.
  auto map_tile = [&](detail::FileRead&& r, std::size_t f) {
    detail::merge_file(std::move(r), files[f], context, acc, files_failed, first_failure);
    std::vector<Footprint> fps = std::move(acc.footprints);
    acc.footprints.clear();
    const auto tile = static_cast<std::uint32_t>(tile_first + extents.size());
    detail::Box extent = detail::empty_box();
    for (const Footprint& fp : fps)
      for (const Polygon& p : fp.polygons) {
        for (const Point2& q : p.outer) detail::grow(extent, q.x, q.y);
        for (const Ring& h : p.holes)
          for (const Point2& q : h) detail::grow(extent, q.x, q.y);
      }
    extents.push_back(extent);
    ++share.tiles;
    share.bytes += sizes[f];
    ts.max_tile_footprints = std::max(ts.max_tile_footprints, fps.size());
    if (next_local + fps.size() > std::numeric_limits<std::uint32_t>::max())
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
        m = static_cast<std::uint32_t>(next_local + m);
      }
      out->spill.append(gp, members, tile, box_of(gp.polygon.outer));
    }
    ts.tile_plans += plans.size();
    next_local += fps.size();
    union_wall += seconds_since(t_union);
  };

  // Until the working CRS is known the files are read one by one (the first georeferenced one decides it), by
  // rank 0; the others learn the CRS from it and how far it read, and the files left are cut into contiguous
  // runs of about equal bytes, one a rank.
  // With the working CRS guessed from the first tile's first building (rank 0), the first tile is read side by side
  // with the others, in the context it is read in alone (`first`), and every rank starts at once; rank 0 checks the
  // guess once that tile is read.
  std::size_t fi = 0;
  std::string guess;
  const detail::ReadContext first = context;
  if (me == 0) {
    if (context.working_definition.empty() && files.size() > 1)
      guess = detail::guess_working_definition(files[0], options, context);
    acc.reading.crs_guessed = !guess.empty();
    for (; guess.empty() && fi < files.size() && context.working_definition.empty(); ++fi) {
      map_tile(detail::read_file(files[fi], options, context, threads, 0, bytes), fi);
      ts.tiles_in_flight = std::max<std::size_t>(ts.tiles_in_flight, 1);
    }
    if (!guess.empty()) context.working_definition = guess;
  }
  std::vector<std::size_t> bounds{0, files.size()};
  if (ranks > 1) {
    detail::Packer p;
    if (me == 0) {
      p.put(static_cast<std::uint64_t>(fi));
      p.str(context.working_definition);
      p.str(context.unknown_frame_file);
    }
    std::vector<std::uint64_t> parts;
    const std::vector<char> all = ex.allgather(p.bytes, &parts);
    detail::Unpacker u(all.data(), static_cast<std::size_t>(parts.at(0)));
    const auto read_by_0 = static_cast<std::size_t>(u.get<std::uint64_t>());
    context.working_definition = u.str();
    context.unknown_frame_file = u.str();
    bounds = detail::split_by_bytes(sizes, ranks, read_by_0);
    tile_first = bounds[static_cast<std::size_t>(me)];
    if (me != 0) fi = tile_first;
  }
  const std::size_t tile_end = bounds[static_cast<std::size_t>(me) + 1];
  std::uint64_t share_read = 0;  // bytes of this rank's run of tiles read so far (told to rank 0)
  const std::function<void(std::uint64_t)> heard = [&](std::uint64_t n) {  // rank 0: bytes other ranks read
    ts.progress_bytes_heard += n;
    bytes.add(n);
  };
  while (fi < tile_end) {
    const std::size_t n = std::min(threads, tile_end - fi);
    std::uint64_t shared = 0;
    for (std::size_t k = 0; k < n; ++k) shared += sizes[fi + k];
    std::vector<detail::FileRead> reads(n);
    const detail::ReadContext fixed = context;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k)
        reads[k] = detail::read_file(files[fi + k], options, guess.empty() || fi + k ? fixed : first, threads, shared,
                                     bytes);
    }, tbb::simple_partitioner());
    if (!guess.empty() && fi == 0) {
      if (!detail::guess_held(reads[0], files[0], first, guess))  // never seen; the tiles read with it are wrong
        throw Error("tiled run: " + files[0] + " fixed another working CRS than its first building said (" + guess +
                    "); run it with --tiles off");
      context = first;  // merge_file fixes it from the first tile, as without the guess
    }
    for (std::size_t k = 0; k < n; ++k) map_tile(std::move(reads[k]), fi + k);
    ts.tiles_in_flight = std::max(ts.tiles_in_flight, n);
    fi += n;
    share_read += shared;
    if (ranks > 1 && me != 0) ex.tell_progress(share_read, fi == tile_end);
    if (ranks > 1 && me == 0) ex.heard_progress(false, heard);
  }
  // Every rank's word that it has read all of its tiles (rank 0 shows their bytes while it waits for them).
  if (ranks > 1 && me != 0 && tile_first == tile_end) ex.tell_progress(0, true);
  if (ranks > 1 && me == 0) ex.heard_progress(true, heard);
  out->spill.flush();
  ts.spill_bytes = out->spill.size();
  share.footprints = static_cast<std::size_t>(next_local);
  share.map_s = seconds_since(t_map);

  // Every rank's tile extents (its tiles are a contiguous run, so rank order is file order) and footprint count
  // (its offset in the global footprint order).
  std::vector<std::uint32_t> id_offset(static_cast<std::size_t>(ranks), 0);
  std::uint64_t footprints_total = next_local;
  if (ranks > 1) {
    detail::Packer p;
    p.put(next_local);
    for (const detail::Box& b : extents)
      for (double v : b) p.put(v);
    std::vector<std::uint64_t> parts;
    const std::vector<char> all = ex.allgather(p.bytes, &parts);
    extents.clear();
    footprints_total = 0;
    std::size_t at = 0;
    for (int r = 0; r < ranks; ++r) {
      detail::Unpacker u(all.data() + at, static_cast<std::size_t>(parts[static_cast<std::size_t>(r)]));
      id_offset[static_cast<std::size_t>(r)] = static_cast<std::uint32_t>(footprints_total);
      footprints_total += u.get<std::uint64_t>();
      if (footprints_total > std::numeric_limits<std::uint32_t>::max())
        throw InputError("tiled run: more than 2^32 footprints");
      const std::size_t n = bounds[static_cast<std::size_t>(r) + 1] - bounds[static_cast<std::size_t>(r)];
      for (std::size_t k = 0; k < n; ++k) {
        detail::Box b;
        for (double& v : b) v = u.get<double>();
        extents.push_back(b);
      }
      at += static_cast<std::size_t>(parts[static_cast<std::size_t>(r)]);
    }
  }
  if (extents.size() != files.size()) throw Error("tiled run: tile extents of " + std::to_string(extents.size()) +
                                                  " tiles for " + std::to_string(files.size()) + " files");
  detail::Box all = detail::empty_box();
  for (const detail::Box& e : extents)
    if (e[0] <= e[2]) {
      detail::grow(all, e[0], e[1]);
      detail::grow(all, e[2], e[3]);
    }

  // Classify this rank's plans: final when the box meets no other tile's extent, else a seam (its footprints
  // kept, members made global).
  progress.report(0.9, "seams");
  const auto t_reduce = clock_type::now();
  const detail::TileExtents index(std::move(extents));
  const std::uint32_t my_offset = id_offset[static_cast<std::size_t>(me)];
  Finals map_finals, reduce_finals;
  std::vector<detail::SpilledPlan> held;  // seams not final yet
  for (std::uint64_t at = 0; at < out->spill.size();) {
    const std::uint64_t here = at;
    detail::SpilledPlan s = out->spill.read(at, true, &at);
    if (!index.meets_other(s.box, s.tile)) {
      map_finals.add(here, s.ids.size());
      continue;
    }
    ++ts.seam_plans;
    ts.seam_footprints += s.ids.size();
    for (std::uint32_t& m : s.ids) m += my_offset;
    s.plan.members = s.ids;
    held.push_back(std::move(s));
  }
  ts.final_plans = map_finals.offsets.size();

  // The reduce: a tree over the ranks. First each rank unites its own seams (a group of one rank); then in
  // round k, rank r with r % 2^(k+1) == 2^k sends what is still open to rank r - 2^k, which unites it with its
  // own. A plan is final once its box meets no tile extent outside the group's tiles (contiguous: the ranks'
  // runs); final plans go to the rank's spill, ids global.
  // `again` false: only this rank's own open plans, already united: they are classified for the larger group.
  auto unite = [&](int group_end, bool again) {
    std::vector<detail::SpilledPlan> plans;
    if (again) {
      share.seam_footprints += std::accumulate(held.begin(), held.end(), std::size_t{0},
                                               [](std::size_t n, const detail::SpilledPlan& s) { return n + s.ids.size(); });
      UnionStats us;
      plans = unite_seams(std::move(held), options.union_params, acc.problems, us);
      acc.blocks += us.blocks;
      acc.timings.blocks_s += us.blocks_s;
    } else {
      plans = std::move(held);
    }
    held.clear();
    const auto first = static_cast<std::uint32_t>(bounds[static_cast<std::size_t>(me)]);
    const auto last = static_cast<std::uint32_t>(bounds[static_cast<std::size_t>(group_end)]);
    for (detail::SpilledPlan& sp : plans) {
      if (index.meets_outside(sp.box, first, last)) {
        held.push_back(std::move(sp));
        continue;
      }
      sp.tile = first;
      reduce_finals.add(out->spill.append(sp.plan, pointers(sp.footprints), sp.tile, sp.box), sp.ids.size());
    }
  };
  if (!held.empty()) unite(me + 1, true);
  for (int step = 1; step < ranks; step *= 2) {
    ++ts.reduce_rounds;
    if (me % (2 * step) == step) {
      std::vector<char> bytes;
      for (const detail::SpilledPlan& s : held)
        detail::PlanSpill::encode(s.plan, pointers(s.footprints), s.tile, s.box, bytes);
      ex.send(me - step, bytes);
      held.clear();
      break;
    }
    if (me % (2 * step) == 0 && me + step < ranks) {
      std::vector<detail::SpilledPlan> got = detail::PlanSpill::decode_all(ex.receive(me + step), true);
      const bool again = !got.empty();
      std::move(got.begin(), got.end(), std::back_inserter(held));
      if (!held.empty()) unite(std::min(me + 2 * step, ranks), again);
    }
  }
  if (!held.empty()) throw Error("tiled run: seam plans left open after the reduce (tile extents inconsistent)");
  ts.reduced_plans = reduce_finals.offsets.size();
  out->spill.flush();
  share.reduce_s = seconds_since(t_reduce);

  // Rank 0 gathers: every rank's final plans of the map (rank order = tile order), then those of the reduce,
  // streamed; then counts and problems. The other ranks keep nothing.
  const auto t_gather = clock_type::now();
  const bool kept = final_plans == FinalPlans::kept_by_each_rank && ranks > 1;
  if (kept) {
    number_kept_plans(map_finals, reduce_finals, my_offset, *out, ex);
  } else if (me == 0) {
    for (std::size_t i = 0; i < map_finals.offsets.size(); ++i) out->add_final(map_finals.offsets[i], map_finals.members[i]);
    for (int r = 1; r < ranks; ++r) receive_finals(r, *out, ex);
    for (std::size_t i = 0; i < reduce_finals.offsets.size(); ++i)
      out->add_final(reduce_finals.offsets[i], reduce_finals.members[i]);
    for (int r = 1; r < ranks; ++r) receive_finals(r, *out, ex);
    out->spill.flush();
  } else {
    stream_finals(out->spill, map_finals, my_offset, ex);
    stream_finals(out->spill, reduce_finals, 0, ex);
  }
  share.gather_s = seconds_since(t_gather);
  share.cpu_s = process_cpu_seconds() - cpu0;
  share.peak_rss_bytes = peak_rss_bytes();
  std::uint64_t failed_total = 0;
  if (ranks > 1) {
    RankPart part{&acc, &ts, &share, files_failed};
    detail::Packer p;
    pack_part(part, p);
    if (me != 0) {
      ex.send(0, p.bytes);
      if (!kept) return std::make_unique<SpilledResult>();
      out->crs_wkt = acc.crs_wkt;  // its plans only: counts and problems are rank 0's
      out->crs_name = acc.crs_name;
      std::copy(all.begin(), all.end(), out->extent);
      return out;
    }
    PipelineResult sum;
    sum.crs_wkt = acc.crs_wkt;
    sum.crs_name = acc.crs_name;
    sum.reading = acc.reading;
    sum.reading.files_chunked = sum.reading.chunks = 0;
    TileStats tsum;
    tsum.tiles = ts.tiles;
    tsum.reduce_rounds = ts.reduce_rounds;
    tsum.progress_bytes_heard = ts.progress_bytes_heard;
    for (int r = 0; r < ranks; ++r) {
      const std::vector<char> bytes = r == 0 ? p.bytes : ex.receive(r);
      detail::Unpacker u(bytes.data(), bytes.size());
      add_part(u, sum, tsum, out->ranks, failed_total);
    }
    const std::string backend = acc.raster_backend;
    acc = std::move(sum);
    if (acc.raster_backend.empty()) acc.raster_backend = backend;
    tsum.spill_bytes = std::max(tsum.spill_bytes, out->spill.size());
    ts = tsum;
  } else {
    failed_total = files_failed;
    out->ranks.push_back(share);
    ts.map_s = share.map_s;
    ts.reduce_s = share.reduce_s;
  }
  if (failed_total == files.size() && footprints_total == 0 && options.unreadable_throws)
    throw InputError(first_failure.empty() ? "no input file could be read" : first_failure);

  out->problems = std::move(acc.problems);
  out->footprints = static_cast<std::size_t>(footprints_total);
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

std::vector<char> LocalExchange::allgather(const std::vector<char>& mine, std::vector<std::uint64_t>* sizes) {
  if (sizes) *sizes = {mine.size()};
  return mine;
}

void LocalExchange::send(int to, const std::vector<char>&) {
  throw std::logic_error("tiled run: one process has no rank " + std::to_string(to) + " to send to");
}

std::vector<char> LocalExchange::receive(int from) {
  throw std::logic_error("tiled run: one process has no rank " + std::to_string(from) + " to receive from");
}

std::unique_ptr<TiledResult> run_pipeline_tiled(const PipelineOptions& options, const Progress& progress) {
  LocalExchange one;
  return run_pipeline_tiled(options, one, progress);
}

std::unique_ptr<TiledResult> run_pipeline_tiled(const PipelineOptions& options, TileExchange& exchange,
                                                const Progress& progress, FinalPlans final_plans) {
  if (options.threads < 0) throw InvalidArgument("threads: " + std::to_string(options.threads) + " is not >= 1 (0 = all cores)");
  if (options.detail.any())
    throw InvalidArgument("tiles: a level of detail (--snap, --close-gaps, --simplify, --min-area, --preset ...) "
                          "looks past a plan's own box; use --tiles off");
  const std::size_t threads = thread_count(options.threads);
  tbb::task_arena arena(static_cast<int>(threads));
  std::unique_ptr<TiledResult> result;
  arena.execute([&] { result = run_tiled(options, progress, threads, exchange, final_plans); });
  return result;
}

}  // namespace groundplan::gis

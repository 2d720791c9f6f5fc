// SPDX-License-Identifier: MIT
// read -> working frame -> footprints -> union, shared by the OGR driver and the CLI.
#include <groundplan/error.h>
#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/reader.h>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <unordered_set>

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// Files named by the inputs: a file as is, a folder as its input files (CityGML, KML/KMZ, glTF;
/// not .dae, which belong to a .kml beside them) sorted by name.
std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs) {
  std::vector<std::string> files;
  for (const std::string& in : inputs) {
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      std::vector<std::string> found;
      for (const auto& e : fs::directory_iterator(in, ec))
        if (e.is_regular_file() && is_input_name(e.path().filename().string())) found.push_back(e.path().string());
      std::sort(found.begin(), found.end());
      if (found.empty())
        throw InputError(in + ": folder holds no input file (*.gml, *.citygml, *.xml, *.kml, *.kmz, *.gltf, *.glb)");
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(in, ec) || in.rfind("/vsi", 0) == 0 || looks_like_connection_string(in)) {
      files.push_back(in);
    } else {
      throw InputError(in + ": no such file or folder");
    }
  }
  return files;
}

FootprintSource to_core(FootprintMode m) {
  switch (m) {
    case FootprintMode::Auto: return FootprintSource::Auto;
    case FootprintMode::GroundSurface: return FootprintSource::GroundSurface;
    case FootprintMode::Decompose: return FootprintSource::Decompose;
  }
  return FootprintSource::Auto;
}

}  // namespace

const char* to_string(FootprintMode mode) {
  switch (mode) {
    case FootprintMode::Auto: return "auto";
    case FootprintMode::GroundSurface: return "ground-surface";
    case FootprintMode::Decompose: return "decompose";
  }
  return "?";
}

FootprintMode footprint_mode_from_string(const std::string& s) {
  const std::string l = lower(s);
  if (l == "auto") return FootprintMode::Auto;
  if (l == "ground-surface" || l == "ground_surface" || l == "groundsurface") return FootprintMode::GroundSurface;
  if (l == "decompose") return FootprintMode::Decompose;
  throw InvalidArgument("footprints: '" + s + "' is not one of auto, ground-surface, decompose");
}

Device device_from_string(const std::string& s) {
  const std::string l = lower(s);
  if (l == "auto") return Device::Auto;
  if (l == "cpu") return Device::Cpu;
  if (l == "cuda" || l == "gpu") return Device::Cuda;
  throw InvalidArgument("device: '" + s + "' is not one of auto, cpu, cuda");
}

LodParams lod_preset(const std::string& name) {
  const std::string l = lower(name);
  LodParams p;
  if (l == "none" || l == "exact" || l.empty()) return p;
  if (l == "cfd") {
    // Values for city-scale CFD meshes with cells of 0.5-2 m near buildings (docs/level_of_detail.md).
    p.snap_m = 0.01;           // digitising precision of LoD1/LoD2 walls; joins party walls drawn twice
    p.close_gaps_m = 0.5;      // a passage narrower than one fine cell carries no resolved flow
    p.simplify_m = 0.1;        // a fifth of the finest cell: shapes the mesh can see do not change
    p.min_hole_area_m2 = 1.0;  // a closed yard under 1 m2 holds fewer than 2x2 fine cells
    p.min_area_m2 = 1.0;       // posts and chimneys modelled as buildings: below 2x2 fine cells
    return p;
  }
  throw InvalidArgument("preset: '" + name + "' is not one of none, cfd");
}

AxisOrder axis_order_from_string(const std::string& s) {
  const std::string l = lower(s);
  if (l == "auto") return AxisOrder::Auto;
  if (l == "east-north" || l == "east_north" || l == "lon-lat" || l == "xy") return AxisOrder::EastNorth;
  if (l == "north-east" || l == "north_east" || l == "lat-lon" || l == "yx") return AxisOrder::NorthEast;
  throw InvalidArgument("axis order: '" + s + "' is not one of auto, east-north, north-east");
}

bool raster_mode_from_string(const std::string& s) {
  const std::string l = lower(s);
  if (l == "exact") return false;
  if (l == "raster") return true;
  throw InvalidArgument("resolution mode: '" + s + "' is not one of exact, raster");
}

PipelineResult run_pipeline(const PipelineOptions& options, const Progress& progress) {
  PipelineResult result;
  const std::vector<std::string> files = expand_inputs(options.inputs);

  ReadOptions read_options;
  read_options.lod = options.lod;
  read_options.origin = options.origin;
  read_options.ogr = options.ogr_input;
  FootprintParams footprint_params;
  footprint_params.source = to_core(options.footprints);

  // One working CRS for all inputs: the first file decides it (or -t_srs does); later files are
  // transformed into it.
  std::string working_definition = options.t_srs;
  // A file without CRS keeps its coordinates as written; after that, no georeferenced file can join
  // it (and before it, none can: WorkingFrame refuses an unknown source once a target is set).
  std::string unknown_frame_file;
  std::size_t files_failed = 0;
  std::string first_failure;

  const auto t_read = clock_type::now();
  double footprint_s = 0;
  // Footprints are made on the other cores while this thread reads on (DESIGN.md: one machine, all
  // cores), each into its slot in reading order, so the output and the problems come out exactly as
  // if made one by one. When too many wait, the reader makes the next one itself: memory stays
  // bounded (a slot holds its mesh until its footprint is made).
  struct Slot {
    Mesh mesh;                    // until its footprint is made
    std::size_t file = 0;         // index into files
    std::size_t problem_pos = 0;  // where its problem goes among the others (result.problems.size() then)
    FootprintResult fp;           // fp.footprint.source_id names the building, made or not
  };
  std::deque<Slot> slots;  // stable addresses: a task holds a pointer to its slot
  tbb::task_group footprint_tasks;
  std::atomic<std::size_t> pending{0};
  auto make = [&footprint_params](Slot& s) {
    s.fp = make_footprint(s.mesh, footprint_params);
    s.mesh = Mesh{};
  };
  const std::size_t max_pending = 16 * static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  struct WaitOnExit {  // the tasks use this frame's locals: never leave it with one still running
    tbb::task_group& g;
    ~WaitOnExit() {
      g.cancel();
      try {
        g.wait();
      } catch (...) {
      }
    }
  } wait_on_exit{footprint_tasks};
  for (std::size_t fi = 0; fi < files.size(); ++fi) {
    const std::string& file = files[fi];
    const Progress file_progress = progress.sub(0.6 * static_cast<double>(fi) / static_cast<double>(files.size()),
                                                0.6 * static_cast<double>(fi + 1) / static_cast<double>(files.size()));
    file_progress.report(0, "reading");
    ReadInfo info;
    std::unique_ptr<WorkingFrame> frame;
    read_options.target_srs = working_definition;  // KML/glTF are placed by the reader, in this CRS
    std::unordered_set<std::string> delivered;  // ids of this file's meshes (for the given-up count below)
    const std::size_t first_problem = result.problems.size();
    auto on_mesh = [&](Mesh&& mesh) {
      ++result.buildings_read;
      delivered.insert(mesh.source_id);
      std::string reason;
      bool placed = true;
      try {
        if (!info.in_working_crs && !frame) {
          CrsOptions crs;
          crs.target_srs = working_definition;
          // --axis-order wins; else the order the format fixes (OGR: GDAL's data axis order), else the CRS's rule.
          crs.source_axis = options.source_axis != AxisOrder::Auto ? options.source_axis : info.source_axis;
          frame = std::make_unique<WorkingFrame>(info.source_srs, crs, file);
        }
        const bool georeferenced = info.in_working_crs || (frame && frame->source_known());
        if (georeferenced && !unknown_frame_file.empty())
          throw InvalidArgument(file + ": has a CRS, but " + unknown_frame_file +
                                " (read before it) has none, so their coordinates cannot be combined; give every "
                                "input a CRS, or process them separately");
        placed = !frame || frame->transform(mesh, &reason);
      } catch (const Error& e) {
        // The file's CRS cannot hold this building (EPSG:4326 on metres ...): the file's fault, so the
        // file stops here (the caller's catch); this building is named too, so that it is not lost.
        result.problems.push_back({mesh.source_id, file, "georeference", "CRS_MISMATCH", e.what()});
        ++result.buildings_dropped;
        throw;
      }
      if (!placed) {
        result.problems.push_back({mesh.source_id, file, "georeference", "TRANSFORM_FAILED", reason});
        ++result.buildings_dropped;
        return;
      }
      Slot& slot = slots.emplace_back();
      slot.mesh = std::move(mesh);
      slot.file = fi;
      slot.problem_pos = result.problems.size();
      if (pending.load(std::memory_order_relaxed) >= max_pending) {
        const auto t_fp = clock_type::now();
        make(slot);
        footprint_s += seconds_since(t_fp);
      } else {
        pending.fetch_add(1, std::memory_order_relaxed);
        footprint_tasks.run([&make, &pending, s = &slot] {
          make(*s);
          pending.fetch_sub(1, std::memory_order_relaxed);
        });
      }
      if ((result.buildings_read & 1023) == 0) file_progress.report(0.5, "reading");
    };
    try {
      read_any(file, read_options, on_mesh, result.problems, info);
    } catch (const Cancelled&) {
      throw;
    } catch (const InputError& e) {
      // One unreadable file does not stop the others; it is a problem of its own. Buildings read
      // before the fault stay (a truncated file).
      ++files_failed;
      if (first_failure.empty()) first_failure = e.what();
      result.problems.push_back({"", file, "read", "UNREADABLE_FILE", e.what()});
    } catch (const InvalidArgument& e) {
      // The file's CRS cannot go to the working CRS (its srsName unknown while the first file, or
      // -t_srs, fixed one): the same, a problem of this file. A bad -t_srs fails every file, so the run.
      ++files_failed;
      if (first_failure.empty()) first_failure = e.what();
      result.problems.push_back({"", file, "georeference", "UNREADABLE_FILE", e.what()});
    }
    // Buildings the reader gave up count as read and dropped: nothing is lost silently. Whatever the
    // format, such a building is named by a read-stage Problem and gave no mesh (a building that did
    // give one may have read-stage defects too: a dropped face, a missing xlink).
    std::unordered_set<std::string> given_up;
    for (std::size_t k = first_problem; k < result.problems.size(); ++k) {
      const Problem& p = result.problems[k];
      if (p.stage == "read" && !p.source_id.empty() && p.code != "NOTE" && !delivered.count(p.source_id))
        given_up.insert(p.source_id);
    }
    result.buildings_read += given_up.size();
    result.buildings_dropped += given_up.size();
    if (info.in_working_crs) {
      for (const std::string& note : info.notes) result.problems.push_back({"", file, "georeference", "NOTE", note});
      if (result.crs_wkt.empty() && info.working_crs.known && unknown_frame_file.empty()) {
        result.crs_wkt = info.working_crs.wkt;
        result.crs_name = info.working_crs.epsg ? "EPSG:" + std::to_string(info.working_crs.epsg) : info.working_crs.name;
        if (working_definition.empty()) working_definition = info.working_crs.definition;
      }
    }
    if (frame && !frame->source_known() && !delivered.empty() && working_definition.empty() &&
        unknown_frame_file.empty())
      unknown_frame_file = file;
    if (frame) {
      for (const std::string& note : frame->notes()) result.problems.push_back({"", file, "georeference", "NOTE", note});
      if (result.crs_wkt.empty() && frame->working_crs().known && unknown_frame_file.empty()) {
        result.crs_wkt = frame->working_crs().wkt;
        result.crs_name = frame->working_crs().epsg ? "EPSG:" + std::to_string(frame->working_crs().epsg)
                                                    : frame->working_crs().name;
        if (working_definition.empty()) working_definition = frame->working_crs().definition;
      }
    }
  }
  // read: the reading thread's time less the footprints it made itself; footprints: those, and the
  // wait for the rest after reading (the time they added to the run, not their CPU time).
  const double read_s = seconds_since(t_read) - footprint_s;
  const auto t_wait = clock_type::now();
  footprint_tasks.wait();
  footprint_s += seconds_since(t_wait);
  // In reading order: each footprint, or its problem where it would have stood had it been made
  // on the spot.
  {
    std::vector<Problem> problems;
    problems.reserve(result.problems.size() + slots.size());
    std::size_t next = 0;  // next problem of result.problems to copy
    for (Slot& slot : slots) {
      FootprintResult& fp = slot.fp;
      if (fp.ok) {
        fp.footprint.source_file = files[slot.file];
        fp.footprint.method = to_string(fp.method);
        result.footprints.push_back(std::move(fp.footprint));
        continue;
      }
      for (; next < slot.problem_pos; ++next) problems.push_back(std::move(result.problems[next]));
      problems.push_back({fp.footprint.source_id, files[slot.file], "footprint", fp.code, fp.reason});
      ++result.buildings_dropped;
    }
    for (; next < result.problems.size(); ++next) problems.push_back(std::move(result.problems[next]));
    result.problems = std::move(problems);
    slots.clear();
  }
  if (files_failed == files.size() && result.footprints.empty()) throw InputError(first_failure);
  result.timings.footprints_s = footprint_s;
  result.timings.read_s = read_s;

  const auto t_union = clock_type::now();
  UnionStats union_stats;
  UnionParams union_params = options.union_params;
  union_params.stats = &union_stats;
  result.plans = build_ground_plans(result.footprints, union_params, options.detail, result.problems,
                                    progress.sub(0.6, 1.0), &result.lod_stats);
  result.blocks = union_stats.blocks;
  result.raster_backend = union_stats.backend;
  const LodStats& ls = result.lod_stats;
  result.timings.lod_s = ls.snap_s + ls.close_s + ls.raster_s + ls.simplify_s + ls.filter_s;
  result.timings.blocks_s = union_stats.blocks_s;
  result.timings.union_s = seconds_since(t_union) - union_stats.blocks_s - result.timings.lod_s;
  progress.report(1.0, "done");
  return result;
}

}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
// read -> working frame -> footprints -> union, shared by the OGR driver and the CLI.
#include <groundplan/error.h>
#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/reader.h>

#include "pipeline/file_reading.h"
#include "pipeline/inputs.h"
#include "xml/block_cache.h"

#include <cpl_string.h>
#include <cpl_vsi.h>
#include <sys/resource.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cstring>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
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

/// The OGR files a folder is expanded to (issue 22): one file, one dataset (a .shp's .dbf/.shx/.prj/.cpg
/// belong to it and are not inputs themselves).
bool is_ogr_input_name(const std::string& name) {
  const std::string ext = lower(fs::path(name).extension().string());
  return ext == ".shp" || ext == ".gpkg" || ext == ".fgb" || ext == ".geojson";
}

/// The subfolders of `folder` (at any depth, the first few in name order) that hold input files, for the error
/// that a folder holds none itself: a folder's own files are its inputs, not its subfolders'.
std::vector<std::string> subfolders_with_inputs(const std::string& folder) {
  constexpr std::size_t kNamed = 5, kVisited = 100000;  // a huge tree is not walked whole for a message
  std::set<std::string> named;
  std::error_code ec;
  std::size_t visited = 0;
  fs::recursive_directory_iterator it(folder, fs::directory_options::skip_permission_denied, ec), end;
  for (; !ec && it != end && visited < kVisited; it.increment(ec), ++visited) {
    const std::string name = it->path().filename().string();
    std::error_code fe;
    if (it.depth() == 0 || !it->is_regular_file(fe) || !(is_input_name(name) || is_ogr_input_name(name))) continue;
    named.insert(fs::relative(it->path().parent_path(), folder, fe).generic_string() + "/");
  }
  std::vector<std::string> out(named.begin(), named.end());
  if (out.size() > kNamed) out.resize(kNamed);
  return out;
}

}  // namespace

std::vector<std::string> input_list(const std::string& source) {
  std::error_code ec;
  if (source.find(',') == std::string::npos || fs::exists(source, ec)) return {source};
  std::vector<std::string> inputs;
  const CPLStringList parts(CSLTokenizeString2(source.c_str(), ",", CSLT_HONOURSTRINGS));
  for (int i = 0; i < parts.size(); ++i)
    if (*parts[i]) inputs.emplace_back(parts[i]);
  return inputs;
}

namespace {

/// A file that is a tile's content in a 3D Tiles folder (read through its tileset.json, never on its own there).
bool is_tile_content_name(const std::string& name) {
  const std::string l = lower(name);
  for (const char* ext : {".glb", ".gltf", ".b3dm", ".i3dm", ".cmpt", ".pnts"})
    if (l.size() > std::strlen(ext) && l.compare(l.size() - std::strlen(ext), std::string::npos, ext) == 0) return true;
  return false;
}

}  // namespace

/// Files named by the inputs: a file as is, a folder as its input files (CityGML, KML/KMZ, glTF, CityJSON;
/// not .dae, which belong to a .kml beside them; Shapefile, GeoPackage, FlatGeobuf, GeoJSON) sorted by name,
/// a .zip as its city files.
std::vector<std::string> detail::expand_inputs(const std::vector<std::string>& inputs, std::vector<Problem>& problems) {
  std::vector<std::string> files;
  for (const std::string& in : inputs) {
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      // A 3D Tiles folder: its tileset.json is the entry point, and its tiles (glTF, b3dm, i3dm, cmpt) are read through
      // it, not one by one; city files of other formats beside it are inputs of their own.
      const bool tileset = fs::is_regular_file(fs::path(in) / "tileset.json", ec);
      std::vector<std::string> found;
      if (tileset) files.push_back((fs::path(in) / "tileset.json").string());
      for (const auto& e : fs::directory_iterator(in, ec)) {
        const std::string name = e.path().filename().string();
        if (!e.is_regular_file() || !(is_input_name(name) || is_ogr_input_name(name))) continue;
        if (tileset && (name == "tileset.json" || is_tile_content_name(name))) continue;
        found.push_back(e.path().string());
      }
      std::sort(found.begin(), found.end());
      if (tileset) {
        files.insert(files.end(), found.begin(), found.end());
        continue;
      }
      if (found.empty()) {
        std::string why = in + ": folder holds no input file (" + input_name_patterns() +
                          ", *.shp, *.gpkg, *.fgb, *.geojson)";
        const std::vector<std::string> below = subfolders_with_inputs(in);
        if (!below.empty()) {
          why += "; subfolders are not read, and these hold input files:";
          for (const std::string& b : below) why += " " + b;
          why += " (name one, or several separated by commas)";
        }
        throw InputError(why);
      }
      files.insert(files.end(), found.begin(), found.end());
    } else if (lower(fs::path(in).extension().string()) == ".zip") {
      // A zip of tiles: its input entries, sorted (read through GDAL's /vsizip/, side by side like a folder).
      const std::string root = in.rfind("/vsizip/", 0) == 0 ? in : "/vsizip/" + in;
      std::vector<std::string> found;
      char** list = VSIReadDirRecursive(root.c_str());
      for (char** e = list; e && *e; ++e) {
        const std::string entry(*e);
        const bool escapes = entry.empty() || entry[0] == '/' || entry[0] == '\\' || entry.find("..") != std::string::npos;
        // GDAL 3.6's listing already leaves out "../x" and "/x"; checked again, and said, in case another does not.
        if (escapes && is_input_name(entry))
          problems.push_back({"", in, "read", "UNSAFE_PATH",
                              "zip entry \"" + entry.substr(0, 200) + "\" names a path outside the archive; not read"});
        else if (is_input_name(entry))
          found.push_back(root + "/" + entry);
      }
      CSLDestroy(list);
      if (!fs::exists(in, ec) && in.rfind("/vsi", 0) != 0) throw InputError(in + ": no such file or folder");
      std::sort(found.begin(), found.end());
      if (found.empty() && ogr_can_read(in)) {  // parts.shp.zip: a dataset GDAL reads (issue 22), not tiles
        files.push_back(in);
        continue;
      }
      if (found.empty())
        throw InputError(in + ": the zip holds no input file (" + input_name_patterns() + "), or is not a zip");
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(in, ec) || in.rfind("/vsi", 0) == 0 || looks_like_connection_string(in)) {
      files.push_back(in);
    } else {
      throw InputError(in + ": no such file or folder");
    }
  }
  return files;
}

std::vector<std::string> input_files(const std::vector<std::string>& inputs) {
  std::vector<Problem> ignored;  // unsafe zip entries: said by the run itself
  return detail::expand_inputs(inputs, ignored);
}

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

int threads_from_string(const std::string& s, const std::string& what) {
  const std::string l = lower(s);
  if (l == "all_cpus" || l == "0") return 0;
  int n = 0;
  const auto [end, ec] = std::from_chars(l.data(), l.data() + l.size(), n);
  if (ec != std::errc() || end != l.data() + l.size() || n < 1)
    throw InvalidArgument(what + "=" + s + ": not a number of threads (1, 2, ... or ALL_CPUS)");
  return n;
}

bool raster_mode_from_string(const std::string& s) {
  const std::string l = lower(s);
  if (l == "exact") return false;
  if (l == "raster") return true;
  throw InvalidArgument("resolution mode: '" + s + "' is not one of exact, raster");
}

std::uint64_t detail::total_bytes(const std::vector<std::string>& files) {
  std::uint64_t total = 0;
  for (const std::string& f : files) {
    VSIStatBufL st;
    if (VSIStatL(f.c_str(), &st) == 0) total += static_cast<std::uint64_t>(st.st_size);
  }
  return total;
}

/// Adds one file's outcome to the result, in file order, and fixes the working CRS from it the way
/// reading the files one after the other always has: the first georeferenced file decides (or -t_srs).
void detail::merge_file(detail::FileRead&& r, const std::string& file, detail::ReadContext& context,
                        PipelineResult& result, std::size_t& files_failed, std::string& first_failure) {
  result.timings.footprints_s += r.footprint_wait_s;
  result.buildings_read += r.buildings_read;
  result.buildings_dropped += r.buildings_dropped;
  if (result.footprints.empty()) {
    result.footprints = std::move(r.footprints);  // the first file: no element moved one by one
  } else {
    result.footprints.reserve(result.footprints.size() + r.footprints.size());
    std::move(r.footprints.begin(), r.footprints.end(), std::back_inserter(result.footprints));
  }
  std::move(r.problems.begin(), r.problems.end(), std::back_inserter(result.problems));
  result.files_read.insert(result.files_read.end(), r.files_opened.begin(), r.files_opened.end());
  if (r.failed) {
    ++files_failed;
    if (first_failure.empty()) first_failure = r.failure;
  }
  detail::fix_crs(r, file, context, result);
  if (r.chunks) {
    ++result.reading.files_chunked;
    result.reading.chunks += r.chunks;
  } else if (!r.whole_reason.empty()) {
    result.reading.read_whole.emplace_back(file, r.whole_reason);
  }
  if (!r.xml_streamed_why.empty()) result.reading.xml_streamed.emplace_back(file, r.xml_streamed_why);
}

void detail::fix_crs(const detail::FileRead& r, const std::string& file, detail::ReadContext& context,
                     PipelineResult& result) {
  auto take = [&](const WorkingCrs& crs) {
    if (!result.crs_wkt.empty() || !crs.known || !context.unknown_frame_file.empty()) return;
    result.crs_wkt = crs.wkt;
    result.crs_name = crs.epsg ? "EPSG:" + std::to_string(crs.epsg) : crs.name;
    if (context.working_definition.empty()) context.working_definition = crs.definition;
  };
  if (r.in_working_crs) take(r.reader_crs);
  // A file without CRS keeps its coordinates as written; after that, no georeferenced file can join it
  // (and before it, none can: WorkingFrame refuses an unknown source once a target is set).
  if (r.has_frame && !r.frame_source_known && r.delivered && context.working_definition.empty() &&
      context.unknown_frame_file.empty())
    context.unknown_frame_file = file;
  if (r.has_frame) take(r.frame_crs);
}

bool detail::guess_held(const detail::FileRead& first, const std::string& file, const detail::ReadContext& before,
                        const std::string& guess) {
  detail::ReadContext after = before;
  PipelineResult crs_only;
  fix_crs(first, file, after, crs_only);
  return after.working_definition == guess && after.unknown_frame_file.empty();
}

namespace {

/// True when the file's footprints are in a CRS (placed by their format, or read through a frame of a known CRS).
bool georeferenced(const detail::FileRead& r) {
  return (r.in_working_crs && r.reader_crs.known) || (r.has_frame && r.frame_source_known && r.frame_crs.known);
}

/// A georeferenced file read after files without CRS (`without_crs`: each file and its CRS as written): those files
/// are set aside as they are when read after it (file_reading.cpp, Placer::without_crs), so that the files' order
/// does not decide which are kept: each of their footprints becomes a NO_CRS problem (the building is dropped), each
/// file gets one NO_CRS problem naming the cause and -s_srs, and their notes about a missing CRS go.
void set_aside_files_without_crs(const std::vector<std::pair<std::string, std::string>>& without_crs,
                                 const detail::FileRead& georeferenced_file, PipelineResult& result) {
  const WorkingCrs& crs = georeferenced_file.in_working_crs ? georeferenced_file.reader_crs : georeferenced_file.frame_crs;
  const std::string name = crs.epsg ? "EPSG:" + std::to_string(crs.epsg) : crs.name;
  std::set<std::string> files;
  for (const auto& f : without_crs) files.insert(f.first);
  std::erase_if(result.problems, [&](const Problem& p) {
    return p.code == "NOTE" && p.stage == "georeference" && p.source_id.empty() && files.count(p.file);
  });
  for (const Footprint& f : result.footprints)
    result.problems.push_back({f.source_id, f.source_file, "georeference", "NO_CRS",
                               "its file has no CRS, unlike the other inputs (" + name +
                                   "): left out (the file's NO_CRS problem says more)"});
  for (const auto& [file, srs] : without_crs)
    result.problems.push_back(
        {"", file, "georeference", "NO_CRS", detail::no_crs_reason(file, detail::no_crs_cause(srs), name)});
  result.buildings_dropped += result.footprints.size();
  result.footprints.clear();
}

/// Moves the footprints of reads[from..] to the end of `out`, in file order, side by side, and frees the files'
/// emptied vectors the same way (merge_file then has none to move). One by one, the 15 later tiles of a 16-tile
/// folder of the 1.5 GB city (186k footprints) cost one thread ~60 ms (tests/bench/RESULTS.md, "The serial steps
/// around the parallel reading").
void append_footprints(std::vector<detail::FileRead>& reads, std::size_t from, std::vector<Footprint>& out) {
  const std::size_t n = reads.size() - from;
  std::vector<std::size_t> at(n + 1, out.size());
  for (std::size_t k = 0; k < n; ++k) at[k + 1] = at[k] + reads[from + k].footprints.size();
  if (at[n] == at[0]) return;
  out.resize(at[n]);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t k) {
    std::vector<Footprint>& src = reads[from + k].footprints;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, src.size(), 2048), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) out[at[k] + i] = std::move(src[i]);
    });
    std::vector<Footprint>().swap(src);
  });
}

PipelineResult run(const PipelineOptions& options, const Progress& progress, std::size_t threads) {
  const double cpu0 = process_cpu_seconds();
  PipelineResult result;
  const std::vector<std::string> files = detail::expand_inputs(options.inputs, result.problems);
  result.reading.files = files.size();
  result.reading.threads = threads;
  result.reading.bytes = detail::total_bytes(files);

  // One working CRS for all inputs: the first file decides it (or -t_srs does); later files are
  // transformed into it. Until it is known the files are read one by one (each may still be read in
  // chunks side by side); from then on a file's reading depends on nothing read before it, so the
  // rest are read side by side and merged in file order: the same result as one by one.
  detail::ReadContext context;
  context.working_definition = options.t_srs;
  context.georeferenced_wins = true;
  std::size_t files_failed = 0;
  std::string first_failure;
  const auto t_read = clock_type::now();
  detail::ByteProgress bytes(progress.sub(0, 0.6), result.reading.bytes);
  progress.report(0, "reading");
  std::size_t fi = 0;
  std::vector<std::pair<std::string, std::string>> without_crs;  // files read so far without CRS, and what they say
  // The working CRS guessed from the first file's first building: then the first file is read side by side with
  // the others (in the context it is read in alone), not before them.
  std::string guess = context.working_definition.empty() && files.size() > 1
                          ? detail::guess_working_definition(files[0], options, context)
                          : std::string{};
  std::vector<detail::FileRead> reads;
  for (;;) {
    for (; guess.empty() && fi < files.size() && context.working_definition.empty(); ++fi) {
      detail::FileRead r = detail::read_file(files[fi], options, context, threads, 0, bytes);
      if (!without_crs.empty() && georeferenced(r)) {
        set_aside_files_without_crs(without_crs, r, result);
        without_crs.clear();
        context.unknown_frame_file.clear();
      } else if (r.has_frame && !r.frame_source_known && r.delivered) {
        without_crs.emplace_back(files[fi], r.frame_srs);
      }
      detail::merge_file(std::move(r), files[fi], context, result, files_failed, first_failure);
    }
    if (fi == files.size()) break;
    // Largest first, so that a big file does not start last; at most one task a thread in flight, so
    // memory holds the footprints kept and one reading per thread.
    std::vector<std::size_t> order(files.size() - fi);
    std::vector<std::uint64_t> size(files.size(), 0);
    for (std::size_t k = 0; k < order.size(); ++k) {
      order[k] = fi + k;
      VSIStatBufL st;
      if (VSIStatL(files[fi + k].c_str(), &st) == 0) size[fi + k] = static_cast<std::uint64_t>(st.st_size);
    }
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return size[a] > size[b]; });
    std::uint64_t shared = 0;  // the bytes these files share the threads with
    for (std::size_t f : order) shared += size[f];
    std::vector<detail::FileRead>(files.size()).swap(reads);
    detail::ReadContext fixed = context;
    if (!guess.empty()) fixed.working_definition = guess;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k)  // with a guess, the first file as it is read alone
        reads[order[k]] = detail::read_file(files[order[k]], options, guess.empty() || order[k] ? fixed : context,
                                            threads, shared, bytes);
    }, tbb::simple_partitioner());
    if (guess.empty() || detail::guess_held(reads[0], files[0], context, guess)) break;
    guess.clear();  // not what the first file fixed (never seen): read again the way without a guess
  }
  result.reading.crs_guessed = !guess.empty();
  if (fi < files.size()) {
    if (result.footprints.empty()) {  // the first file's vector taken whole, as merge_file takes it
      result.footprints = std::move(reads[fi].footprints);
      reads[fi].footprints.clear();
    }
    append_footprints(reads, fi, result.footprints);
    for (; fi < files.size(); ++fi)
      detail::merge_file(std::move(reads[fi]), files[fi], context, result, files_failed, first_failure);
  }
  std::sort(result.files_read.begin(), result.files_read.end());
  result.files_read.erase(std::unique(result.files_read.begin(), result.files_read.end()), result.files_read.end());
  xml::release_cached_blocks();  // the reading threads' spare memory, before the union needs its own
  if (files_failed == files.size() && result.footprints.empty() && options.unreadable_throws)
    throw InputError(first_failure);
  result.timings.read_s = std::max(0.0, seconds_since(t_read) - result.timings.footprints_s);

  const auto t_union = clock_type::now();
  UnionStats union_stats;
  UnionParams union_params = options.union_params;
  union_params.stats = &union_stats;
  if (options.plan_feed && !options.detail.any()) union_params.feed = options.plan_feed(result);
  result.plans = build_ground_plans(result.footprints, union_params, options.detail, result.problems,
                                    progress.sub(0.6, 1.0), &result.lod_stats);
  result.blocks = union_stats.blocks;
  result.raster_backend = union_stats.backend;
  const LodStats& ls = result.lod_stats;
  result.timings.lod_s = ls.snap_s + ls.close_s + ls.raster_s + ls.simplify_s + ls.filter_s;
  result.timings.blocks_s = union_stats.blocks_s;
  result.timings.union_s = seconds_since(t_union) - union_stats.blocks_s - result.timings.lod_s;
  result.timings.cpu_s = process_cpu_seconds() - cpu0;
  progress.report(1.0, "done");
  return result;
}

}  // namespace

double process_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

std::size_t thread_count(int requested) {
  if (requested > 0) return static_cast<std::size_t>(requested);
  return static_cast<std::size_t>(std::max(1, tbb::info::default_concurrency()));
}

PipelineResult run_pipeline(const PipelineOptions& options, const Progress& progress) {
  if (options.threads < 0) throw InvalidArgument("threads: " + std::to_string(options.threads) + " is not >= 1 (0 = all cores)");
  const std::size_t threads = thread_count(options.threads);
  // Every stage's parallel work runs in this arena, so --threads bounds all of them.
  tbb::task_arena arena(static_cast<int>(threads));
  PipelineResult result;
  arena.execute([&] { result = run(options, progress, threads); });
  return result;
}

}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
// groundplan: ogr2ogr's syntax with ground plans as the source. Our own flags are taken out here
// (CLI11); everything else goes to GDAL's own ogr2ogr parser (GDALVectorTranslateOptionsNew), so every
// ogr2ogr option behaves as users know it.
#include "ogr_groundplan.h"
#include "open_options.h"
#include "gpkg_rtree.h"
#include "csv_slices.h"
#include "gpkg_slices.h"
#include "preview.h"
#ifdef GROUNDPLAN_WITH_MPI
#include "gpkg_rank_slices.h"
#include "mpi_exchange.h"
#include "rank_writes.h"
#include "staged_output.h"
#include "streamed_gpkg.h"
#endif

#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/gis/lod_choice.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/tiled.h>

#include <CLI/CLI.hpp>
#include <gdal_utils.h>
#include <gdal_version.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

namespace {

#ifdef GROUNDPLAN_WITH_MPI
using Ranks = groundplan::cli::MpiExchange;
#else
/// Without MPI there is one rank and no exchange (nullptr everywhere).
class Ranks {};
#endif

/// Ranks of the run: more than one only under `mpirun -np N` with N > 1 (an MPI build).
int rank_count(Ranks* ranks) {
#ifdef GROUNDPLAN_WITH_MPI
  return ranks ? ranks->size() : 1;
#else
  (void)ranks;
  return 1;
#endif
}

using groundplan::gis::PipelineOptions;
using groundplan::gis::PipelineResult;

/// ogr2ogr options that take values (GDAL 3.6 ogr2ogr_lib.cpp), so that the positional arguments
/// (destination, source, layer names) can be told apart from option values.
int ogr2ogr_arity(const std::string& opt, const std::vector<std::string>& args, std::size_t i) {
  static const std::set<std::string> one = {
      "-f", "-of", "-dsco", "-lco", "-nln", "-nlt", "-t_srs", "-s_srs", "-a_srs", "-where", "-sql", "-dialect",
      "-spat_srs", "-fid", "-select", "-geomfield", "-gt", "-simplify", "-segmentize", "-fieldTypeToString",
      "-mapFieldType", "-fieldmap", "-zfield", "-oo", "-doo", "-mo", "-ct", "-clipsrcsql", "-clipsrclayer",
      "-clipsrcwhere", "-clipdstsql", "-clipdstlayer", "-clipdstwhere", "-datelineoffset", "-limit", "-order",
      "-a_coord_epoch", "-s_coord_epoch", "-t_coord_epoch", "-xyRes", "-zRes", "-mRes", "-dim", "-maxsubfields",
      "-if", "--config", "--debug", "--optfile"};
  if (opt == "-spat") return 4;
  if (opt == "--config") return 2;
  if (opt == "-gcp") {
    // 4 numbers, and an optional fifth (elevation).
    int n = 4;
    if (i + 5 < args.size()) {
      char* end = nullptr;
      std::strtod(args[i + 5].c_str(), &end);
      if (end && *end == '\0' && !args[i + 5].empty()) n = 5;
    }
    return n;
  }
  if (opt == "-clipsrc" || opt == "-clipdst") {
    // Either one value (WKT, datasource, spat_extent) or xmin ymin xmax ymax.
    if (i + 1 < args.size()) {
      char* end = nullptr;
      std::strtod(args[i + 1].c_str(), &end);
      if (end && *end == '\0' && !args[i + 1].empty()) return 4;
    }
    return 1;
  }
  return one.count(opt) ? 1 : 0;
}

struct Ogr2ogrArgs {
  std::vector<std::string> options;  // everything but the two datasource names
  std::vector<std::string> layers;   // layer names given after the source
  std::string dst, src;
  bool progress = false;
  bool quiet = false;
  bool layer_named = false;
  std::string format;
};

Ogr2ogrArgs split_ogr2ogr_args(const std::vector<std::string>& args) {
  Ogr2ogrArgs out;
  std::vector<std::string> positional;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() > 1 && a[0] == '-') {
      const int n = ogr2ogr_arity(a, args, i);
      if (i + static_cast<std::size_t>(n) >= args.size())
        throw groundplan::InvalidArgument("option " + a + " needs " + std::to_string(n) + " value(s)");
      if (a == "-progress") out.progress = true;
      if (a == "-q" || a == "-quiet") out.quiet = true;
      if (a == "-f" || a == "-of") out.format = args[i + 1];
      out.options.push_back(a);
      for (int k = 1; k <= n; ++k) out.options.push_back(args[i + static_cast<std::size_t>(k)]);
      i += static_cast<std::size_t>(n);
    } else {
      positional.push_back(a);
    }
  }
  if (positional.size() < 2)
    throw groundplan::InvalidArgument(
        "expected a destination and a source: groundplan [options] dst_datasource src_file [layer ...]");
  out.dst = positional[0];
  out.src = positional[1];
  for (std::size_t i = 2; i < positional.size(); ++i) {
    out.options.push_back(positional[i]);  // layer names, as ogr2ogr takes them
    out.layers.push_back(positional[i]);
    out.layer_named = true;
  }
  return out;
}

/// -s_srs / -a_srs name the CRS of the source coordinates (issue 16): ours to apply before the union
/// (the srsName is wrong or missing), so they are taken out of what goes to GDAL's ogr2ogr, which would
/// otherwise reproject or relabel our output. The last one given wins.
std::string take_source_srs(std::vector<std::string>& options) {
  std::string srs;
  for (std::size_t i = 0; i + 1 < options.size();) {
    if (options[i] == "-s_srs" || options[i] == "-a_srs") {
      srs = options[i + 1];
      options.erase(options.begin() + static_cast<std::ptrdiff_t>(i), options.begin() + static_cast<std::ptrdiff_t>(i) + 2);
    } else {
      ++i;
    }
  }
  return srs;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// True when the output goes to DBF files (Shapefile): string fields hold at most 254 characters.
bool writes_dbf(const Ogr2ogrArgs& ogr) {
  if (!ogr.format.empty()) return lower(ogr.format) == "esri shapefile";
  const std::string ext = lower(std::filesystem::path(ogr.dst).extension().string());
  return ext == ".shp" || ext == ".dbf";
}

/// True when the CLI builds the GeoPackage's spatial index itself (gpkg_rtree.h): a new local .gpkg written
/// by GDAL < 3.7 (later versions build theirs in a background thread), the user having said nothing of
/// SPATIAL_INDEX (-lco SPATIAL_INDEX=YES asks for GDAL's own) and not adding to an existing file.
bool packs_gpkg_index(const Ogr2ogrArgs& ogr) {
  if (GDAL_VERSION_NUM >= 3070000) return false;
  const std::string ext = lower(std::filesystem::path(ogr.dst).extension().string());
  if (!(ogr.format.empty() ? ext == ".gpkg" : lower(ogr.format) == "gpkg")) return false;
  std::error_code ec;
  if (ogr.dst.rfind("/vsi", 0) == 0 || std::filesystem::exists(ogr.dst, ec)) return false;
  for (std::size_t i = 0; i < ogr.options.size(); ++i) {
    const std::string o = lower(ogr.options[i]);
    if (o == "-append" || o == "-update" || o == "-upsert" || o == "-addfields") return false;
    if (o == "-lco" && i + 1 < ogr.options.size() && lower(ogr.options[i + 1]).rfind("spatial_index=", 0) == 0)
      return false;
  }
  return true;
}

/// Runs GDAL's ogr2ogr on `src` with `args`; false (GDAL has printed why) on failure.
bool vector_translate(const std::string& dst, GDALDatasetH src, const std::vector<std::string>& args, bool progress,
                      int* usage_error) {
  CPLStringList argv;
  for (const auto& a : args) argv.AddString(a.c_str());
  GDALVectorTranslateOptions* vt = GDALVectorTranslateOptionsNew(argv.List(), nullptr);
  if (!vt) {
    *usage_error = TRUE;
    return false;
  }
  if (progress) GDALVectorTranslateOptionsSetProgress(vt, GDALTermProgress, nullptr);
  GDALDatasetH out = GDALVectorTranslate(dst.c_str(), nullptr, 1, &src, vt, usage_error);
  GDALVectorTranslateOptionsFree(vt);
  if (!out) return false;
  // Closing flushes: an error here (disk full ...) is a failure too.
  CPLErrorReset();
  GDALClose(out);
  return CPLGetLastErrorType() < CE_Failure;
}

/// Problems proper, without notes (a CRS guess is worth saying but is no defect).
std::size_t count_defects(const std::vector<groundplan::Problem>& problems) {
  std::size_t n = 0;
  for (const auto& p : problems) n += p.code != "NOTE";
  return n;
}

/// "4 problems" or "4 problems, 36 notes": the summary's count, notes apart.
std::string problems_and_notes(const std::vector<groundplan::Problem>& problems) {
  const std::size_t defects = count_defects(problems), notes = problems.size() - defects;
  std::string s = std::to_string(defects) + (defects == 1 ? " problem" : " problems");
  if (notes) s += ", " + std::to_string(notes) + (notes == 1 ? " note" : " notes");
  return s;
}

/// Whether the output holds a problems layer (named among the layers written).
bool writes_problems(const Ogr2ogrArgs& ogr) {
  return ogr.layer_named && std::any_of(ogr.layers.begin(), ogr.layers.end(),
                                        [](const std::string& l) { return EQUAL(l.c_str(), "problems"); });
}

/// The first problems and notes on stderr, and how many of each are not shown (counted as the summary counts:
/// problems apart from notes). `problems_written`: the dataset whose problems layer holds them all; empty when no
/// problems layer was written.
void print_problems(const std::vector<groundplan::Problem>& problems, const std::string& problems_written = {}) {
  constexpr std::size_t kShown = 20;
  for (std::size_t i = 0; i < problems.size() && i < kShown; ++i) {
    const auto& p = problems[i];
    if (p.source_id.empty())
      std::fprintf(stderr, "groundplan: %s: %s: %s\n", p.file.c_str(), p.code == "NOTE" ? "note" : p.code.c_str(),
                   p.reason.c_str());
    else
      std::fprintf(stderr, "groundplan: %s: building %s: %s (%s)\n", p.file.c_str(), p.source_id.c_str(),
                   p.reason.c_str(), p.code.c_str());
  }
  if (problems.size() <= kShown) return;
  std::size_t notes = 0;
  for (std::size_t i = kShown; i < problems.size(); ++i) notes += problems[i].code == "NOTE";
  const std::size_t defects = problems.size() - kShown - notes;
  std::string more;
  if (defects) more = std::to_string(defects) + (defects == 1 ? " more problem" : " more problems");
  if (notes) more += (more.empty() ? "" : " and ") + std::to_string(notes) + (notes == 1 ? " more note" : " more notes");
  std::fprintf(stderr, "groundplan: ... and %s: %s\n", more.c_str(),
               problems_written.empty() ? "write the 'problems' layer to see them all"
                                        : ("all are in the 'problems' layer of " + problems_written).c_str());
}

std::size_t count_holes(const PipelineResult& r) {
  std::size_t holes = 0;
  for (const auto& p : r.plans) holes += p.polygon.holes.size();
  return holes;
}

/// --stats "spatial_index": the GeoPackage index packed by the CLI (gpkg_rtree.h); one form for the
/// one-process and the tiled run.
nlohmann::json spatial_index_json(const groundplan::cli::RtreeBuild& index) {
  return {{"tables", index.tables},   {"entries", index.entries},   {"read_s", index.read_s}, {"write_s", index.write_s},
          {"commit_s", index.commit_s}, {"error", index.error}, {"by_gdal", index.by_gdal}};
}

/// --stats: counts (buildings = footprints + dropped: nothing lost) and per-stage timings. False (said
/// on stderr) when the file cannot be written.
/// The level-of-detail settings and what they changed (--stats "level_of_detail").
nlohmann::json lod_json(const groundplan::LodParams& p, const groundplan::LodStats& s) {
  return {{"params",
           {{"snap_m", p.snap_m},
            {"close_gaps_m", p.close_gaps_m},
            {"min_hole_area_m2", p.min_hole_area_m2},
            {"min_area_m2", p.min_area_m2},
            {"simplify_m", p.simplify_m},
            {"resolution_mode", p.raster ? "raster" : "exact"}}},
          {"snap", {{"vertices_moved", s.snap_vertices_moved},
                    {"vertices_inserted", s.snap_vertices_inserted},
                    {"rings_collapsed", s.snap_rings_collapsed}}},
          {"close_gaps", {{"plans_before", s.close_plans_before},
                          {"plans_after", s.close_plans_after},
                          {"area_added_m2", s.close_area_added_m2},
                          {"plans_failed", s.close_plans_failed}}},
          {"raster", {{"pixel_m", s.raster_pixel_m}, {"holes_filled", s.raster_holes_filled}}},
          {"simplify", {{"vertices_before", s.simplify_vertices_before},
                        {"vertices_after", s.simplify_vertices_after}}},
          {"min_hole_area", {{"holes_filled", s.holes_filled}, {"area_filled_m2", s.holes_filled_area_m2}}},
          {"min_area", {{"plans_dropped", s.plans_dropped}, {"area_dropped_m2", s.plans_dropped_area_m2}}},
          {"timings_s", {{"snap", s.snap_s}, {"close_gaps", s.close_s}, {"raster", s.raster_s},
                         {"simplify", s.simplify_s}, {"filters", s.filter_s}}}};
}

/// One line for a person: what the level of detail changed.
std::string lod_summary(const groundplan::LodParams& p, const groundplan::LodStats& s) {
  std::string out;
  char buf[256];
  auto add = [&](const char* text) { out += out.empty() ? text : std::string("; ") + text; };
  if (p.snap_m > 0) {
    std::snprintf(buf, sizeof buf, "snap %g m moved %zu vertices, inserted %zu", p.snap_m, s.snap_vertices_moved,
                  s.snap_vertices_inserted);
    add(buf);
  }
  if (p.close_gaps_m > 0) {
    std::snprintf(buf, sizeof buf, "close-gaps %g m: %zu -> %zu plans, +%.3f m2", p.close_gaps_m,
                  s.close_plans_before, s.close_plans_after, s.close_area_added_m2);
    add(buf);
  }
  if (p.raster) {
    std::snprintf(buf, sizeof buf, "raster %g m pixels: %zu holes filled", s.raster_pixel_m, s.raster_holes_filled);
    add(buf);
  }
  if (p.simplify_m > 0) {
    std::snprintf(buf, sizeof buf, "simplify %g m: %zu -> %zu vertices", p.simplify_m, s.simplify_vertices_before,
                  s.simplify_vertices_after);
    add(buf);
  }
  if (p.min_hole_area_m2 > 0) {
    std::snprintf(buf, sizeof buf, "%zu holes under %g m2 filled (%.3g m2)", s.holes_filled, p.min_hole_area_m2,
                  s.holes_filled_area_m2);
    add(buf);
  }
  if (p.min_area_m2 > 0) {
    std::snprintf(buf, sizeof buf, "%zu plans under %g m2 dropped (%.3g m2)", s.plans_dropped, p.min_area_m2,
                  s.plans_dropped_area_m2);
    add(buf);
  }
  return out;
}

using clock = std::chrono::steady_clock;

double seconds_since(clock::time_point t0) { return std::chrono::duration<double>(clock::now() - t0).count(); }

struct WriteOutcome {
  bool ok = false;
  int usage_error = FALSE;
  bool own_index = false;
  double write_s = 0, index_s = 0;
  groundplan::cli::RtreeBuild built;
  std::string members_note;
  nlohmann::json writer;  // --stats "writer": how many writers, and why one (gpkg_slices.h)
};

bool write_stats(const std::string& path, const PipelineResult& result, double write_s, double index_s, double total_s,
                 double cpu_s, const nlohmann::json* verify, const groundplan::LodParams& lod,
                 const WriteOutcome* written = nullptr) {
  nlohmann::json j;
  j["counts"] = {{"buildings", result.buildings_read}, {"footprints", result.footprints.size()},
                 {"dropped", result.buildings_dropped},  {"blocks", result.blocks},
                 {"ground_plans", result.plans.size()},
                 {"holes", count_holes(result)},          {"problems", count_defects(result.problems)},
                 {"notes", result.problems.size() - count_defects(result.problems)}};
  j["timings_s"] = {{"read", result.timings.read_s},     {"footprints", result.timings.footprints_s},
                    {"blocks", result.timings.blocks_s}, {"union", result.timings.union_s},
                    {"level_of_detail", result.timings.lod_s}, {"write", write_s},
                    {"spatial_index", index_s},          {"total", total_s}, {"cpu", cpu_s}};
  const groundplan::gis::ReadStats& rs = result.reading;
  nlohmann::json whole = nlohmann::json::array();
  for (const auto& [file, why] : rs.read_whole) whole.push_back({{"file", file}, {"why", why}});
  nlohmann::json streamed = nlohmann::json::array();
  for (const auto& [file, why] : rs.xml_streamed) streamed.push_back({{"file", file}, {"why", why}});
  j["reading"] = {{"threads", rs.threads}, {"files", rs.files},       {"bytes", rs.bytes},
                  {"files_chunked", rs.files_chunked}, {"chunks", rs.chunks}, {"read_whole", whole},
                  {"xml_streamed", streamed}};
  j["raster_backend"] = result.raster_backend;
  if (written && written->own_index && written->ok)  // the GeoPackage spatial index packed by the CLI (gpkg_rtree.h)
    j["spatial_index"] = spatial_index_json(written->built);
  if (written && !written->writer.is_null()) j["writer"] = written->writer;
  if (lod.any()) j["level_of_detail"] = lod_json(lod, result.lod_stats);
  if (verify) j["verify"] = *verify;
  std::ofstream f(path);
  f << j.dump(2) << '\n';
  if (!f) {
    std::fprintf(stderr, "groundplan: cannot write stats file %s\n", path.c_str());
    return false;
  }
  return true;
}


/// ogr2ogr's options without the layer names (they come last); the layers written.
std::vector<std::string> option_flags(const Ogr2ogrArgs& ogr) {
  return {ogr.options.begin(), ogr.options.end() - static_cast<std::ptrdiff_t>(ogr.layers.size())};
}
std::vector<std::string> written_layers(const Ogr2ogrArgs& ogr) {
  return ogr.layer_named ? ogr.layers : std::vector<std::string>{"ground_plans"};
}

using AnotherDataset = std::function<groundplan::driver::OGRGroundPlanDataSource*(int threads)>;

/// The slices' source over the one-process result: a dataset from `another` (on `threads` threads) serving the plans
/// [first, last); null where it cannot be made, and that slice fails, and so the write (gpkg_slices.h).
groundplan::cli::SliceSource slice_source(const AnotherDataset& another, int threads) {
  return [&another, threads](std::size_t first, std::size_t last) -> GDALDatasetH {
    auto* d = another(threads);
    if (!d || !d->layer("ground_plans")) {
      delete d;
      return nullptr;
    }
    d->layer("ground_plans")->restrict_to(first, last);
    return GDALDataset::ToHandle(d);
  };
}

/// The writer of a new GeoPackage that starts while the union goes on (streamed_gpkg.h), or null where the plans are
/// written after the union: not a new GeoPackage whose index the CLI packs, an ogr2ogr option that rules slices out
/// (gpkg_slices.h), a level of detail (its steps change the union's plans), one thread, or
/// `--config GROUNDPLAN_WRITE_DURING_UNION NO`. Whether it is used is known once the union has begun (enough plans).
std::unique_ptr<groundplan::cli::StreamedGpkg> stream_plans(const Ogr2ogrArgs& ogr, const PipelineOptions& options,
                                                            std::size_t id_chars) {
  if (!CPLTestBool(CPLGetConfigOption("GROUNDPLAN_WRITE_DURING_UNION", "YES"))) return nullptr;
  if (!packs_gpkg_index(ogr) || options.detail.any()) return nullptr;
  const int threads = static_cast<int>(groundplan::gis::thread_count(options.threads));
  if (threads < 2) return nullptr;
  groundplan::cli::StreamedGpkg::Setup setup;
  setup.write.dst = ogr.dst;
  setup.write.flags = option_flags(ogr);
  setup.write.flags.insert(setup.write.flags.end(), {"-lco", "SPATIAL_INDEX=NO"});  // packed afterwards, as write_output
  setup.write.layers = written_layers(ogr);
  if (!groundplan::cli::slices_ruled_out(setup.write.flags, setup.write.layers, "ground_plans").empty()) return nullptr;
  setup.write.progress = ogr.progress && !ogr.quiet;
  setup.threads = threads;
  setup.id_chars = id_chars;
  setup.translate = vector_translate;
  return std::make_unique<groundplan::cli::StreamedGpkg>(std::move(setup));
}

/// Writes our dataset (taking it: closed here) through GDAL's ogr2ogr with the user's options, packs a new
/// GeoPackage's spatial index, and writes the full member lists beside a DBF whose id lists were cut.
/// `another`, where given, makes one more dataset like `ds` (the one-process result): a new GeoPackage is then
/// written by several writers side by side (gpkg_slices.h).
WriteOutcome write_output(groundplan::driver::OGRGroundPlanDataSource* ds, const Ogr2ogrArgs& ogr, int threads,
                          const AnotherDataset& another = {}, groundplan::cli::StreamedGpkg* streamed = nullptr) {
  WriteOutcome w;
  const bool dbf = writes_dbf(ogr);
  GDALDatasetH src_h = GDALDataset::ToHandle(ds);
  // Streamed, the destination exists by now: it is the new GeoPackage the index is packed for.
  const bool own_index = (streamed && streamed->engaged()) || packs_gpkg_index(ogr);
  w.own_index = own_index;
  std::vector<std::string> flags = option_flags(ogr);
  if (own_index) flags.insert(flags.end(), {"-lco", "SPATIAL_INDEX=NO"});
  const std::vector<std::string> layers = written_layers(ogr);
  std::vector<std::string> vt_args = flags;
  vt_args.insert(vt_args.end(), layers.begin(), layers.end());
  const auto t_write = clock::now();
  int usage_error = FALSE;
  bool write_ok = false;
  const int n_threads = static_cast<int>(groundplan::gis::thread_count(threads));
  std::string why_one = "not a new GeoPackage or CSV file";
  int writers = 1;
  // A new GeoPackage or CSV file: the plans written by several writers side by side (gpkg_slices.h, csv_slices.h).
  std::error_code exists_ec;
  const bool csv = !own_index && groundplan::cli::is_csv_file(ogr.format, ogr.dst) &&
                   !std::filesystem::exists(ogr.dst, exists_ec);
  if (streamed && streamed->engaged() && another) {
    // The slices were written while the union went on (streamed_gpkg.h): slice 0 where it carries other layers,
    // then what is left of the writing and appending.
    writers = 0;
    const auto out = streamed->finish(slice_source(another, std::max(1, n_threads / streamed->writers())));
    write_ok = out.ok;
    if (!out.ok) std::fprintf(stderr, "groundplan: %s\n", out.error.c_str());
    w.writer = {{"writers", streamed->writers()},
                {"during_union", true},
                {"slices", streamed->slices()},
                {"slices_started_during_union", streamed->slices_before_end()},
                {"slices_s", out.slices_s},
                {"after_union_s", out.merge_s}};
  } else if ((own_index || csv) && another) {
    auto* plans_layer = ds->layer("ground_plans");
    const std::size_t plans = plans_layer ? static_cast<std::size_t>(plans_layer->GetFeatureCount(TRUE)) : 0;
    writers = csv ? groundplan::cli::csv_writers(flags, layers, "ground_plans", plans, n_threads, &why_one)
                  : groundplan::cli::gpkg_writers(flags, layers, "ground_plans", plans, n_threads, &why_one);
    if (writers > 1) {
      groundplan::cli::SliceWrite sw;
      sw.dst = ogr.dst;
      sw.flags = flags;
      sw.layers = layers;
      sw.plans = plans;
      sw.writers = writers;
      sw.progress = ogr.progress && !ogr.quiet;
      const groundplan::cli::SliceSource source = slice_source(another, std::max(1, n_threads / writers));
      const auto slice = csv ? groundplan::cli::write_csv_slices(sw, source, vector_translate)
                             : groundplan::cli::write_gpkg_slices(sw, source, vector_translate);
      write_ok = slice.ok;
      usage_error = slice.usage_error;
      if (!slice.ok) std::fprintf(stderr, "groundplan: %s\n", slice.error.c_str());
      w.writer = {{"writers", writers}, {"slices_s", slice.slices_s}, {"append_s", slice.merge_s}};
    }
  }
  if (writers == 1) {
    write_ok = vector_translate(ogr.dst, src_h, vt_args, ogr.progress && !ogr.quiet, &usage_error);
    w.writer = {{"writers", 1}, {"why_one", why_one}};
  }
  double index_s = 0;
  groundplan::cli::RtreeBuild& built = w.built;
  if (write_ok && own_index) {
    const auto t_index = clock::now();
    const bool indexed = groundplan::cli::index_new_gpkg(
        ogr.dst, static_cast<int>(groundplan::gis::thread_count(threads)), built);
    if (built.by_gdal)
      std::fprintf(stderr, "groundplan: note: packing the spatial index failed (%s); GDAL built it instead\n",
                   built.error.c_str());
    if (!indexed) std::fprintf(stderr, "groundplan: warning: %s has no spatial index\n", ogr.dst.c_str());
    index_s = seconds_since(t_index);
  }
  // DBF fields hold 254 characters: cut lists are marked "...(+N)" and the full lists go beside them.
  std::string& members_note = w.members_note;
  const bool members_named =
      std::find(ogr.layers.begin(), ogr.layers.end(), std::string("plan_members")) != ogr.layers.end();
  if (write_ok && dbf && ds->id_lists_cut() && !members_named) {
    std::filesystem::path dst(ogr.dst);
    const bool single_file = lower(dst.extension().string()) == ".shp";
    const std::string dir = single_file ? (dst.has_parent_path() ? dst.parent_path().string() : ".") : ogr.dst;
    const std::string name = (single_file ? dst.stem().string() : std::string("ground_plans")) + "_members";
    std::vector<std::string> args = {"-f", "ESRI Shapefile", "-nln", name, "plan_members"};
    if (std::find(ogr.options.begin(), ogr.options.end(), "-overwrite") != ogr.options.end())
      args.insert(args.begin(), "-overwrite");
    write_ok = vector_translate(dir, src_h, args, false, &usage_error);
    members_note = std::to_string(ds->id_lists_cut()) +
                   " plans list more building ids than a DBF field holds (254 characters): their building_ids end "
                   "in '...(+N)'; the full lists are in " +
                   (std::filesystem::path(dir) / (name + ".dbf")).string() + " (gp_id, fp_id, source_id, bldg_id)";
  }
  GDALClose(src_h);
  w.ok = write_ok;
  w.usage_error = usage_error;
  w.write_s = seconds_since(t_write);
  w.index_s = index_s;
  return w;
}

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

/// Nothing usable (every building a problem, or no building at all): the problems layer alone is written where it
/// was asked for (through `ds`, taken and closed here; null: nothing is written, as a rank of a run over ranks does),
/// no empty ground plans that would look like a result; the problems and why nothing else is written go to stderr.
/// The run fails all the same.
void say_nothing_usable(const std::vector<groundplan::Problem>& problems, std::size_t buildings_read,
                        const Ogr2ogrArgs& ogr, GDALDataset* ds) {
  bool wrote = false;
  if (ds) {
    GDALDatasetH h = GDALDataset::ToHandle(ds);
    if (writes_problems(ogr)) {
      std::vector<std::string> args = option_flags(ogr);
      args.push_back("problems");
      int usage_error = FALSE;
      wrote = vector_translate(ogr.dst, h, args, false, &usage_error);
      if (!wrote) std::fprintf(stderr, "groundplan: could not write the problems layer to %s\n", ogr.dst.c_str());
    }
    GDALClose(h);
  }
  if (!ogr.quiet) print_problems(problems, wrote ? ogr.dst : std::string());
  const std::string why = buildings_read == 0
                              ? "no building found"
                              : std::to_string(buildings_read) + " buildings read, none gave a footprint";
  std::fprintf(stderr, "groundplan: %s: nothing usable: %s; %s\n", ogr.src.c_str(), why.c_str(),
               wrote ? ("only the 'problems' layer written, to " + ogr.dst).c_str() : "nothing written");
}

/// ogr2ogr's options without the layer names (they come last), and the layers written (ground_plans unless named).
/// --stats of a tiled run (one process or ranks): counts, timings, "tiles", "mpi". `plans`: in the whole dataset
/// (rank 0 of a run whose ranks write their own plans holds none of theirs). False (said) when it cannot be written.
bool write_tiled_stats(const std::string& stats_path, const groundplan::gis::TiledResult& r, std::size_t plans,
                       double write_s, double index_s, const WriteOutcome* written, double total_s,
                       double cpu_s) {
  if (stats_path.empty()) return true;
  const groundplan::gis::TileStats& t = r.tiles;
  nlohmann::json j;
  j["counts"] = {{"buildings", r.buildings_read}, {"footprints", r.footprints}, {"dropped", r.buildings_dropped},
                 {"blocks", r.blocks}, {"ground_plans", plans}, {"problems", count_defects(r.problems)},
                 {"notes", r.problems.size() - count_defects(r.problems)}};
  j["timings_s"] = {{"read", r.timings.read_s}, {"footprints", r.timings.footprints_s}, {"blocks", r.timings.blocks_s},
                    {"union", r.timings.union_s}, {"write", write_s}, {"spatial_index", index_s},
                    {"total", total_s}, {"cpu", cpu_s}};
  j["reading"] = {{"threads", r.reading.threads}, {"files", r.reading.files}, {"bytes", r.reading.bytes},
                  {"files_chunked", r.reading.files_chunked}, {"chunks", r.reading.chunks}};
  j["tiles"] = {{"tiles", t.tiles}, {"tile_plans", t.tile_plans}, {"final_at_once", t.final_plans},
                {"seam_plans", t.seam_plans}, {"seam_footprints", t.seam_footprints},
                {"plans_from_seams", t.reduced_plans}, {"max_tile_footprints", t.max_tile_footprints},
                {"tiles_in_flight", t.tiles_in_flight}, {"spill_bytes", t.spill_bytes},
                {"map_s", t.map_s}, {"reduce_s", t.reduce_s}};
  if (r.ranks.size() > 1) {  // the run over MPI ranks: each rank's share
    nlohmann::json per_rank = nlohmann::json::array();
    for (const groundplan::gis::RankStats& s : r.ranks)
      per_rank.push_back({{"tiles", s.tiles}, {"bytes", s.bytes}, {"footprints", s.footprints},
                          {"seam_footprints_united", s.seam_footprints}, {"map_s", s.map_s},
                          {"reduce_s", s.reduce_s}, {"gather_s", s.gather_s}, {"cpu_s", s.cpu_s},
                          {"peak_rss_bytes", s.peak_rss_bytes}});
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    j["mpi"] = {{"ranks", r.ranks.size()}, {"reduce_rounds", t.reduce_rounds}, {"per_rank", per_rank},
                {"progress_bytes_heard", t.progress_bytes_heard},
                {"rank0_peak_rss_after_write_bytes", static_cast<std::uint64_t>(u.ru_maxrss) * 1024}};
  }
  j["raster_backend"] = r.raster_backend;
  if (written && written->own_index && written->ok) j["spatial_index"] = spatial_index_json(written->built);
  if (written && !written->writer.is_null()) j["writer"] = written->writer;
  std::ofstream f(stats_path);
  f << j.dump(2) << '\n';
  if (!f) std::fprintf(stderr, "groundplan: cannot write stats file %s\n", stats_path.c_str());
  return static_cast<bool>(f);
}

/// What a tiled run says when it has written (unless -q): counts, the tiles' share, timings, problems.
void print_tiled_summary(const groundplan::gis::TiledResult& r, const Ogr2ogrArgs& ogr, const std::string& dst,
                         std::size_t plans, double total_s, double write_s) {
  const groundplan::gis::TileStats& t = r.tiles;
  std::printf("groundplan: read %zu buildings from %s (CRS %s) in %zu tiles%s\n", r.buildings_read, ogr.src.c_str(),
              r.crs_name.empty() ? "unknown" : r.crs_name.c_str(), t.tiles,
              r.ranks.size() > 1 ? (" on " + std::to_string(r.ranks.size()) + " MPI ranks").c_str() : "");
  std::printf("groundplan: %zu footprints -> %zu ground plans (%zu final at once, %zu from %zu seam plans of "
              "%zu footprints); %s\n",
              r.footprints, plans, t.final_plans, t.reduced_plans, t.seam_plans, t.seam_footprints,
              problems_and_notes(r.problems).c_str());
  std::printf("groundplan: wrote %s in %.2f s (map %.2f s, reduce %.2f s, write %.2f s)\n", dst.c_str(), total_s,
              t.map_s, t.reduce_s, write_s);
  print_problems(r.problems, writes_problems(ogr) ? dst : std::string());
}

#ifdef GROUNDPLAN_WITH_MPI
/// A tiled result without plans or problems, in `like`'s CRS: the layers rank 0 makes the tables from.
class NoPlans final : public groundplan::gis::TiledResult {
 public:
  explicit NoPlans(const groundplan::gis::TiledResult& like) {
    crs_wkt = like.crs_wkt;
    crs_name = like.crs_name;
  }
  std::size_t plan_count() const override { return 0; }
  groundplan::gis::StoredPlan plan(std::size_t) const override { throw std::out_of_range("NoPlans has no plan"); }
  std::uint64_t members_before(std::size_t) const override { return 0; }
};

/// The tiled run over ranks, every rank keeping its own final plans to write them itself.
std::shared_ptr<const groundplan::gis::TiledResult> tiled_kept_by_each_rank(const PipelineOptions& options,
                                                                        const groundplan::Progress& progress,
                                                                        Ranks& ranks) {
  return groundplan::gis::run_pipeline_tiled(options, ranks, ranks.rank() == 0 ? progress : groundplan::Progress{},
                                             groundplan::gis::FinalPlans::kept_by_each_rank);
}

/// The tiled run over ranks into PostgreSQL (issue 15 stage 5, rank_writes.h): every rank writes its own final
/// plans into the tables rank 0 makes, each in a transaction committed once all have written.
int run_tiled_into_database(const PipelineOptions& options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                            const groundplan::Progress& progress, Ranks& ranks) {
  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  const bool root = ranks.rank() == 0;
  std::shared_ptr<const groundplan::gis::TiledResult> result = tiled_kept_by_each_rank(options, progress, ranks);
  const groundplan::gis::TiledResult& r = *result;
  const std::size_t plans = r.tiles.final_plans + r.tiles.reduced_plans;  // rank 0: over all ranks
  groundplan::cli::TableSetup setup;
  setup.dst = ogr.dst;
  setup.options = ogr.options;
  if (!ogr.layer_named) setup.options.push_back("ground_plans");
  const std::vector<std::string> layers = written_layers(ogr);
  const std::string nln = groundplan::cli::table_name(option_flags(ogr), "");
  for (const std::string& l : layers) setup.tables.push_back(layers.size() == 1 && !nln.empty() ? nln : l);
  if (root && r.footprints == 0) {
    say_nothing_usable(r.problems, r.buildings_read, ogr, nullptr);
    setup.create = false;
  }
  auto* mine = new groundplan::driver::OGRGroundPlanDataSource(std::string(groundplan::driver::kPrefix) + ogr.src,
                                                               result, 0, options.threads);
  auto* empty = new groundplan::driver::OGRGroundPlanDataSource(
      std::string(groundplan::driver::kPrefix) + ogr.src, std::make_shared<const NoPlans>(r), 0, options.threads);
  const groundplan::cli::RankWrite w = groundplan::cli::write_from_every_rank(
      ranks, setup, mine, empty, [&ranks] { ranks.test_point("commit"); });
  if (!root) return w.ok ? 0 : 1;
  if (!ogr.quiet)
    for (const std::string& s : w.left_over)
      std::fprintf(stderr, "groundplan: warning: the database holds the staging schema of another run: %s\n", s.c_str());
  for (const std::string& s : w.warnings) std::fprintf(stderr, "groundplan: warning: %s\n", s.c_str());
  if (!setup.create) {
    write_tiled_stats(stats_path, r, 0, 0, 0, nullptr, seconds_since(t0), groundplan::gis::process_cpu_seconds() - cpu0);
    return 1;
  }
  if (!w.ok) {
    std::fprintf(stderr, "groundplan: could not write %s: %s\n", ogr.dst.c_str(), w.why.c_str());
    return 1;
  }
  WriteOutcome wo;  // --stats "writer": where the tables were made before they went into the user's schema
  wo.ok = true;
  wo.writer = {{"writers", ranks.size()}, {"every_rank_writes", true}};
  if (w.in_place.empty()) wo.writer["staging_schema"] = w.staging_schema;
  else wo.writer["tables_made_in_place"] = w.in_place;
  const int rc = write_tiled_stats(stats_path, r, plans, w.write_s, 0, &wo, seconds_since(t0),
                                   groundplan::gis::process_cpu_seconds() - cpu0) ? 0 : 1;
  if (!ogr.quiet) print_tiled_summary(r, ogr, ogr.dst + " (every rank its own plans)", plans, seconds_since(t0), w.write_s);
  return rc;
}
#endif

#ifdef GROUNDPLAN_WITH_MPI
/// Under mpirun into a file: why rank 0 writes every plan (gathered to it), rather than every rank its own into a
/// GeoPackage slice (gpkg_rank_slices.h); empty: every rank writes. Collective, before the run (the ranks keep
/// their plans or stream them). Rank 0 decides: a new local GeoPackage whose index the CLI packs, and ogr2ogr
/// options that act on each feature alone (gpkg_slices.h slices_ruled_out); then it leaves a file with a token
/// beside the destination, which every rank must read back: the slices go into that folder, so a rank on a host
/// that does not share it (no shared file system) would write where rank 0 cannot read.
std::string why_rank_0_writes(const Ogr2ogrArgs& ogr, Ranks& ranks) {
  namespace fs = std::filesystem;
  std::string said, marker;
  if (ranks.rank() == 0) {
    std::string why = packs_gpkg_index(ogr) ? groundplan::cli::slices_ruled_out(option_flags(ogr), written_layers(ogr),
                                                                                "ground_plans")
                                            : "not a new local GeoPackage whose spatial index the CLI packs";
    std::string token;
    if (why.empty()) {
      const fs::path dst(ogr.dst);
      marker = ((dst.has_parent_path() ? dst.parent_path() : fs::path(".")) /
                (".groundplan-shared-" + std::to_string(::getpid())))
                   .string();
      token = std::to_string(::getpid()) + "-" + std::to_string(clock::now().time_since_epoch().count());
      std::ofstream f(marker);
      f << token;
      f.close();
      if (!f) why = "cannot write beside " + ogr.dst;
    }
    said = why.empty() ? marker + "\n" + token : "!" + why;
  }
  said = ranks.broadcast(said);
  int sees = 1;
  if (ranks.rank() != 0 && !said.empty() && said[0] != '!') {
    const std::size_t nl = said.find('\n');
    std::ifstream f(said.substr(0, nl));
    std::string got;
    std::getline(f, got);
    sees = f.is_open() && got == said.substr(nl + 1) && !ranks.test_pretends("shared");
  }
  const std::vector<int> all = ranks.every_rank(sees);
  if (!marker.empty()) {
    std::error_code ec;
    fs::remove(marker, ec);
  }
  if (said.empty() || said[0] == '!') return said.empty() ? std::string("rank 0 said nothing") : said.substr(1);
  std::string blind;
  for (std::size_t r = 0; r < all.size(); ++r)
    if (!all[r]) blind += (blind.empty() ? "" : ", ") + std::to_string(r);
  if (!blind.empty())
    return "the destination's folder is not seen by rank " + blind + " (not a file system every rank shares)";
  return {};
}

/// The tiled run over ranks into a new GeoPackage (gpkg_rank_slices.h): every rank writes its own final plans into a
/// slice beside rank 0's staged destination, side by side; rank 0 appends the slices in FID order, packs the
/// spatial index, and moves the file into place once every rank has finished.
int run_tiled_gpkg_by_ranks(const PipelineOptions& options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                            const groundplan::Progress& progress, Ranks& ranks) {
  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  const bool root = ranks.rank() == 0;
  std::shared_ptr<const groundplan::gis::TiledResult> result = tiled_kept_by_each_rank(options, progress, ranks);
  const groundplan::gis::TiledResult& r = *result;
  const std::size_t plans = r.tiles.final_plans + r.tiles.reduced_plans;  // rank 0: over all ranks
  std::unique_ptr<groundplan::cli::StagedOutput> staged;
  groundplan::cli::RankGpkgWrite w;
  w.flags = option_flags(ogr);
  w.flags.insert(w.flags.end(), {"-lco", "SPATIAL_INDEX=NO"});  // packed once the slices are in (gpkg_rtree.h)
  w.layers = written_layers(ogr);
  w.progress = ogr.progress && !ogr.quiet;
  if (root) {
    staged = std::make_unique<groundplan::cli::StagedOutput>(ogr.dst);
    w.dst = staged->path();
    const std::filesystem::path dst(w.dst);
    w.folder = dst.has_parent_path() ? dst.parent_path().string() : ".";
    if (r.footprints == 0) {
      say_nothing_usable(r.problems, r.buildings_read, ogr, nullptr);
      w.nothing = true;
    }
  }
  const std::string ds_name = std::string(groundplan::driver::kPrefix) + ogr.src;
  const auto t_write = clock::now();
  const groundplan::cli::RankGpkgOutcome o = groundplan::cli::write_gpkg_from_every_rank(
      ranks, w, r,
      [&] {
        return GDALDataset::ToHandle(new groundplan::driver::OGRGroundPlanDataSource(ds_name, result, 0, options.threads));
      },
      vector_translate, [&ranks] { ranks.test_point("slice"); });
  if (!root) {
    ranks.barrier();  // rank 0 has appended the slices
    return 0;
  }
  // Every rank waits for rank 0 here before the dataset is moved into place; rank 0's outcome is its return code.
  auto finish = [&](int rc) {
    ranks.barrier();
    if (rc == 0) staged->commit();
    return rc;
  };
  auto stats = [&](std::size_t n, double write_s, double index_s, const WriteOutcome* written) {
    return write_tiled_stats(stats_path, r, n, write_s, index_s, written, seconds_since(t0),
                             groundplan::gis::process_cpu_seconds() - cpu0);
  };
  if (o.nothing) {
    stats(0, 0, 0, nullptr);
    return finish(1);
  }
  if (!o.ok) {
    std::fprintf(stderr, "groundplan: could not write %s%s: %s\n", ogr.dst.c_str(),
                 o.usage_error ? " (bad ogr2ogr options)" : "", o.why.c_str());
    return finish(1);
  }
  WriteOutcome wo;
  wo.ok = wo.own_index = true;
  const auto t_index = clock::now();
  const bool indexed = groundplan::cli::index_new_gpkg(
      w.dst, static_cast<int>(groundplan::gis::thread_count(options.threads)), wo.built);
  if (wo.built.by_gdal)
    std::fprintf(stderr, "groundplan: note: packing the spatial index failed (%s); GDAL built it instead\n",
                 wo.built.error.c_str());
  if (!indexed) std::fprintf(stderr, "groundplan: warning: %s has no spatial index\n", ogr.dst.c_str());
  wo.index_s = seconds_since(t_index);
  wo.write_s = seconds_since(t_write);
  wo.writer = {{"writers", ranks.size()}, {"by", "every rank, a slice each"}, {"slice_s", o.slice_s},
               {"append_s", o.append_s}};
  const int rc = finish(stats(plans, wo.write_s, wo.index_s, &wo) ? 0 : 1);
  if (!ogr.quiet) print_tiled_summary(r, ogr, ogr.dst, plans, seconds_since(t0), wo.write_s);
  return rc;
}
#endif

/// The tiled run (issue 15, gis/tiled.h): same plans with bounded memory; the final plans of all tiles first,
/// then the plans from seams. --stats says how many were final at once and how many were seams.
int run_tiled(const PipelineOptions& options, const Ogr2ogrArgs& ogr_in, const std::string& stats_path,
              const groundplan::Progress& progress, Ranks* ranks) {
  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  std::shared_ptr<const groundplan::gis::TiledResult> result;
  Ogr2ogrArgs ogr = ogr_in;
#ifdef GROUNDPLAN_WITH_MPI
  // Over ranks (issue 15): the dataset is written into a staging folder that is moved into place once every rank
  // has finished (staged_output.h). A database: every rank writes its own plans (stage 5); a new GeoPackage: every
  // rank writes a slice (below); other files: rank 0 gets every plan and writes them all, the others only map and
  // reduce.
  std::unique_ptr<groundplan::cli::StagedOutput> staged;
  if (rank_count(ranks) > 1 && groundplan::cli::written_by_every_rank(ogr.format, ogr.dst))
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
    staged = std::make_unique<groundplan::cli::StagedOutput>(ogr.dst);
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
  if (!result) result = groundplan::gis::run_pipeline_tiled(options, progress);
  const groundplan::gis::TiledResult& r = *result;
  auto stats = [&](double write_s, double index_s, const WriteOutcome* written) {
    return write_tiled_stats(stats_path, r, r.plan_count(), write_s, index_s, written, seconds_since(t0),
                             groundplan::gis::process_cpu_seconds() - cpu0);
  };
  const std::string ds_name = std::string(groundplan::driver::kPrefix) + ogr.src;
  const std::size_t id_chars = writes_dbf(ogr) ? 254 : 0;
  if (r.footprints == 0) {
    // Over ranks the output is staged and not committed on failure: nothing is written there.
    say_nothing_usable(r.problems, r.buildings_read, ogr,
                       rank_count(ranks) > 1 ? nullptr
                                             : new groundplan::driver::OGRGroundPlanDataSource(ds_name, result, id_chars,
                                                                                               options.threads));
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

int run(int argc, char** argv, Ranks* ranks) {
  CLI::App app{
      "groundplan: ground plans (the exact union of building footprints) from 3D city models.\n"
      "Usage: groundplan [groundplan options] [ogr2ogr options] dst_datasource src_file_or_folder [layer ...]\n"
      "Layers: ground_plans (default), footprints, problems. Every ogr2ogr option works (-f, -t_srs, -lco, -nln,\n"
      "-where, -spat, -progress, -overwrite, -append, ...). Example:\n"
      "  groundplan -f GPKG plans.gpkg city.gml ground_plans problems",
      "groundplan"};
  app.allow_extras();
  app.set_version_flag("--version", std::string("groundplan ") + GROUNDPLAN_VERSION + " (GDAL " +
                                        GDALVersionInfo("RELEASE_NAME") +
#ifdef GROUNDPLAN_WITH_MPI
                                        ", MPI: " + groundplan::cli::mpi_version() +
#endif
                                        ")");
  double resolution = 0;
  std::string device = "auto", footprints = "auto", stats_path, preview_path, origin;
  std::string lod = "-1";
  bool verify = false;
  app.add_option("--resolution", resolution, "Raster pixel in metres for blocks and seeds (0 = automatic); exact "
                                              "result whatever the value")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--device", device, "auto|cpu|cuda: where blocks are rasterised (auto: the GPU from 500k footprints)");
  app.add_option("--footprints", footprints, "auto|ground-surface|decompose: where footprints come from");
  app.add_option("--origin", origin, "lon,lat[,alt] where a glTF without georeference or a bare .dae sits");
  std::string axis_order = "auto";
  app.add_option("--axis-order", axis_order,
                 "auto|east-north|north-east: CityGML axis order when a file breaks its CRS's rule (e.g. EPSG:4979 "
                 "written lon,lat); auto follows the CRS");
  // OGR sources (issue 22): named --input-* so that ogr2ogr's -sql/-where/layer names keep meaning the output.
  groundplan::gis::OgrInputOptions ogr_in;
  app.add_option("--input-layer", ogr_in.layers, "OGR source: a layer to read (repeat for more; default: all)");
  app.add_option("--input-where", ogr_in.where, "OGR source: attribute filter on the layers read (OGR SQL WHERE)");
  app.add_option("--input-sql", ogr_in.sql, "OGR source: SQL statement whose result layer is read");
  app.add_option("--input-dialect", ogr_in.dialect, "OGR source: dialect of --input-sql (OGRSQL, SQLITE)");
  app.add_option("--input-oo", ogr_in.open_options, "OGR source: NAME=VALUE open option of its driver (repeatable)");
  app.add_option("--id-field", ogr_in.id_field, "OGR source: field holding the building id (default: the FID)");
  app.add_option("--group-by", ogr_in.group_by, "OGR source: features sharing this field's value are one building");
  app.add_option("--input-geom-field", ogr_in.geom_field,
                 "OGR source: the geometry field to read where a layer has several (default: the first)");
  app.add_option("--lod", lod, "Level of detail to read: -1 (highest per building), 0..4, or with CityJSON's "
                               "refinement as 3DBAG names it (1.2, 1.3, 2.2)");
  app.add_flag("--verify", verify, "Compare with GEOS UnaryUnion of the same footprints; exit 3 on mismatch");
  app.add_option("--stats", stats_path, "Write counts and per-stage timings to this JSON file");
  app.add_option("--preview", preview_path, "Write a PNG map of the plans (holes open, problem buildings in red)");
  std::string tiles = "auto";
  app.add_option("--tiles", tiles,
                 "auto|on|off: map the input files one tile at a time with bounded memory, the plans crossing tile "
                 "edges united at the end (same plans; final plans first, then those from seams). auto: on where one "
                 "process would hold over a quarter of the memory (estimated from the file sizes), in 2 or more "
                 "files, unless --verify, --preview, a level of detail or the footprints layer needs everything at "
                 "once");
  int threads = 0;
  std::int64_t read_chunk_bytes = 0, read_range_features = 0;
  auto* o_threads = app.add_option("--threads", threads, "Threads for every stage (0 = all cores; default: GDAL's "
                                                         "GDAL_NUM_THREADS config option, else all cores)")
                        ->check(CLI::NonNegativeNumber);
  app.add_option("--read-chunk-bytes", read_chunk_bytes,
                 "CityGML files are cut into chunks of about this many bytes read side by side (0 = automatic, "
                 "-1 = never); the result is the same either way");
  app.add_option("--read-range-features", read_range_features,
                 "OGR sources are cut into ranges of about this many features read side by side, one dataset handle "
                 "each (0 = automatic, -1 = never); the result is the same either way");
  // Level of detail (issue 9, docs/level_of_detail.md): off by default, the exact union.
  std::string preset = "none", resolution_mode = "exact";
  groundplan::LodParams lod_flags;
  auto* o_preset = app.add_option("--preset", preset, "Level-of-detail preset: none|cfd (cfd = --snap 0.01 "
                                                      "--close-gaps 0.5 --simplify 0.1 --min-hole-area 1 --min-area 1; "
                                                      "flags given explicitly override it)");
  auto* o_mode = app.add_option("--resolution-mode", resolution_mode,
                                "exact|raster: raster = the paper's level of detail, holes that hold no whole "
                                "--resolution pixel are filled");
  auto* o_snap = app.add_option("--snap", lod_flags.snap_m, "Metres: vertices and edges closer than this become "
                                                            "shared before the union (micro-gaps and slivers close)")
                     ->check(CLI::NonNegativeNumber);
  auto* o_close = app.add_option("--close-gaps", lod_flags.close_gaps_m,
                                 "Metres: gaps and cavities narrower than this close (closing with mitre joins)")
                      ->check(CLI::NonNegativeNumber);
  auto* o_min_hole = app.add_option("--min-hole-area", lod_flags.min_hole_area_m2, "m2: smaller holes are filled")
                         ->check(CLI::NonNegativeNumber);
  auto* o_min_area = app.add_option("--min-area", lod_flags.min_area_m2,
                                    "m2: smaller ground plans are dropped (their buildings go to 'problems')")
                         ->check(CLI::NonNegativeNumber);
  auto* o_simplify = app.add_option("--simplify", lod_flags.simplify_m,
                                    "Metres: topology-preserving simplification (plans stay valid, never overlap)")
                         ->check(CLI::NonNegativeNumber);

  // Our flags first (so that --version and --help are ours, not GDAL's), then GDAL's own general
  // options (--config, --debug, --formats ...) on what is left.
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  GDALAllRegister();
  groundplan::driver::register_driver();
  CPLStringList gdal_argv;
  gdal_argv.AddString(argv[0]);
  for (const std::string& a : app.remaining()) gdal_argv.AddString(a.c_str());
  char** gdal_args = gdal_argv.StealList();
  const int gdal_argc = GDALGeneralCmdLineProcessor(CSLCount(gdal_args), &gdal_args, 0);
  std::vector<std::string> rest;
  for (int i = 1; i < gdal_argc; ++i) rest.emplace_back(gdal_args[i]);
  CSLDestroy(gdal_args);
  if (gdal_argc < 1) return 0;  // --formats and friends were answered
  if (rest.empty()) {
    std::cout << app.help();
    return 1;
  }
  Ogr2ogrArgs ogr = split_ogr2ogr_args(rest);

  PipelineOptions options;
  options.inputs = groundplan::gis::input_list(ogr.src);  // a file or folder, or several separated by commas
  options.s_srs = take_source_srs(ogr.options);
  options.union_params.resolution_m = resolution;
  options.union_params.device = groundplan::gis::device_from_string(device);
  options.footprints = groundplan::gis::footprint_mode_from_string(footprints);
  const groundplan::gis::LodChoice lod_choice = groundplan::gis::parse_lod_choice(lod, "--lod ");
  options.lod = lod_choice.lod;
  options.lod_refinement = lod_choice.refinement;
  options.origin = origin;
  options.source_axis = groundplan::gis::axis_order_from_string(axis_order);
  options.ogr_input = ogr_in;
  options.detail = groundplan::gis::lod_preset(o_preset->count() ? preset : "none");
  if (o_mode->count()) options.detail.raster = groundplan::gis::raster_mode_from_string(resolution_mode);
  if (o_snap->count()) options.detail.snap_m = lod_flags.snap_m;
  if (o_close->count()) options.detail.close_gaps_m = lod_flags.close_gaps_m;
  if (o_min_hole->count()) options.detail.min_hole_area_m2 = lod_flags.min_hole_area_m2;
  if (o_min_area->count()) options.detail.min_area_m2 = lod_flags.min_area_m2;
  if (o_simplify->count()) options.detail.simplify_m = lod_flags.simplify_m;

  // --threads, else GDAL's GDAL_NUM_THREADS (--config GDAL_NUM_THREADS 4, or the environment), else all cores.
  if (o_threads->count())
    options.threads = threads;
  else if (const char* v = CPLGetConfigOption("GDAL_NUM_THREADS", nullptr))
    options.threads = groundplan::gis::threads_from_string(v, "GDAL_NUM_THREADS");
  options.read_chunk_bytes = read_chunk_bytes;
  options.read_range_features = read_range_features;
  // The problems layer asked for is written even when no input could be read (over ranks the first fault stops
  // every rank, as before).
  options.unreadable_throws = !writes_problems(ogr) || rank_count(ranks) > 1;

  // Tiles (issue 15): a large folder of tiles is mapped tile by tile with bounded memory (same plans).
  const std::string tiles_mode = lower(tiles);
  if (tiles_mode != "auto" && tiles_mode != "on" && tiles_mode != "off")
    throw groundplan::InvalidArgument("--tiles: '" + tiles + "' is not one of auto, on, off");
  const std::string no_tiles = tiles_ruled_out(options, ogr, verify, !preview_path.empty());
  if (tiles_mode == "on" && !no_tiles.empty())
    throw groundplan::InvalidArgument("--tiles on: " + no_tiles + "; use --tiles off");
  bool tiled = tiles_mode == "on";
  if (tiles_mode == "auto" && no_tiles.empty()) tiled = tiles_pay_off(options.inputs);
  if (rank_count(ranks) > 1) {  // mpirun -np N (N > 1): the ranks share the tiled run
    if (tiles_mode == "off" || !no_tiles.empty())
      throw groundplan::InvalidArgument("mpirun -np " + std::to_string(rank_count(ranks)) + ": the ranks share the "
                                        "tiled run, and " + (no_tiles.empty() ? std::string("--tiles off") : no_tiles) +
                                        "; run it without mpirun");
    tiled = true;
  }
  if (tiled) {
    groundplan::Progress tile_progress;
    if (ogr.progress && !ogr.quiet)
      tile_progress = groundplan::Progress([](double f, const char* msg) {
        return GDALTermProgress(f, msg, nullptr) != FALSE;
      });
    return run_tiled(options, ogr, stats_path, tile_progress, ranks);
  }

  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  groundplan::Progress progress;
  if (ogr.progress && !ogr.quiet)
    progress = groundplan::Progress([](double f, const char* msg) {
      return GDALTermProgress(f, msg, nullptr) != FALSE;
    });
  // A new GeoPackage of many plans is written while the union goes on (streamed_gpkg.h).
  const std::size_t id_chars = writes_dbf(ogr) ? 254 : 0;
  std::unique_ptr<groundplan::cli::StreamedGpkg> streamed = stream_plans(ogr, options, id_chars);
  if (streamed)
    options.plan_feed = [&streamed](const PipelineResult& read) { return streamed->engage(read); };
  const auto result_ptr = std::make_shared<const PipelineResult>(groundplan::gis::run_pipeline(options, progress.sub(0, 1)));
  const PipelineResult& result = *result_ptr;

  // Nothing usable (every building a problem, or no building at all): say so and fail, without
  // writing an empty result that would look like success (issue 8). The problems say why.
  const std::string ds_name = std::string(groundplan::driver::kPrefix) + ogr.src;
  if (result.footprints.empty()) {
    say_nothing_usable(result.problems, result.buildings_read, ogr,
                       new groundplan::driver::OGRGroundPlanDataSource(ds_name, result_ptr, id_chars, options.threads));
    if (!stats_path.empty())
      write_stats(stats_path, result, 0, 0, seconds_since(t0), groundplan::gis::process_cpu_seconds() - cpu0, nullptr,
                  options.detail);
    return 1;
  }

  // Hand the result to GDAL's ogr2ogr as an in-memory dataset of our driver.
  auto* ds = new groundplan::driver::OGRGroundPlanDataSource(ds_name, result_ptr, id_chars, options.threads);
  const WriteOutcome w = write_output(ds, ogr, options.threads, [&](int threads) {
    return new groundplan::driver::OGRGroundPlanDataSource(ds_name, result_ptr, id_chars, threads);
  }, streamed.get());
  const bool write_ok = w.ok;
  const double write_s = w.write_s, index_s = w.index_s;
  const std::string& members_note = w.members_note;
  const double total_s = seconds_since(t0), cpu_s = groundplan::gis::process_cpu_seconds() - cpu0;  // before --verify and --preview
  if (!write_ok) {
    std::fprintf(stderr, "groundplan: could not write %s%s\n", ogr.dst.c_str(),
                 w.usage_error ? " (bad ogr2ogr options)" : "");
    return 1;
  }
  if (!members_note.empty()) std::fprintf(stderr, "groundplan: note: %s\n", members_note.c_str());

  const std::size_t holes = count_holes(result);
  if (!ogr.quiet) {
    std::printf("groundplan: read %zu buildings from %s (CRS %s)\n", result.buildings_read, ogr.src.c_str(),
                result.crs_name.empty() ? "unknown" : result.crs_name.c_str());
    std::printf("groundplan: %zu footprints -> %zu ground plans with %zu holes; %s\n", result.footprints.size(),
                result.plans.size(), holes, problems_and_notes(result.problems).c_str());
    std::printf(
        "groundplan: wrote %s in %.2f s (read %.2f s, footprints %.2f s, blocks %.2f s (%zu, %s), union %.2f s, "
        "write %.2f s)\n",
        ogr.dst.c_str(), total_s, result.timings.read_s,
        result.timings.footprints_s, result.timings.blocks_s, result.blocks, result.raster_backend.c_str(),
        result.timings.union_s, write_s);
    if (options.detail.any())
      std::printf("groundplan: level of detail (%.2f s): %s\n", result.timings.lod_s,
                  lod_summary(options.detail, result.lod_stats).c_str());
    print_problems(result.problems, writes_problems(ogr) ? ogr.dst : std::string());
  }

  if (!preview_path.empty()) groundplan::cli::write_preview_png(result, preview_path);

  int rc = 0;
  nlohmann::json verify_json;
  if (verify) {
    const auto c = groundplan::gis::compare_with_geos(result.footprints, result.plans);
    // With a level of detail the plans differ from the exact union on purpose: what must hold is
    // validity and no overlap; the difference is reported.
    const bool lod = options.detail.any();
    const bool ok = lod ? c.invalid_ours == 0 && c.overlapping_ours == 0 : c.matches();
    if (lod)
      std::printf("groundplan: verify (level of detail on): %s: %zu invalid plans, %zu overlapping pairs; against "
                  "the exact GEOS UnaryUnion: area %.6f m2 vs %.6f m2, symmetric difference %.6g m2 (%.3g%%), %zu vs "
                  "%zu polygons, %zu vs %zu holes\n",
                  ok ? "VALID" : "INVALID", c.invalid_ours, c.overlapping_ours, c.area_ours, c.area_geos,
                  c.symdiff_area, c.area_geos > 0 ? 100 * c.symdiff_area / c.area_geos : 0.0, c.polygons_ours,
                  c.polygons_geos, c.holes_ours, c.holes_geos);
    else
      std::printf("groundplan: verify against GEOS UnaryUnion: %s: %s\n", c.matches() ? "MATCH" : "MISMATCH",
                  c.summary().c_str());
    verify_json = {{"match", c.matches()}, {"level_of_detail", lod}, {"valid_and_disjoint", c.invalid_ours == 0 && c.overlapping_ours == 0},        {"symdiff_area_m2", c.symdiff_area}, {"area_m2", c.area_ours},
                   {"area_geos_m2", c.area_geos}, {"polygons", c.polygons_ours},      {"polygons_geos", c.polygons_geos},
                   {"holes", c.holes_ours},       {"holes_geos", c.holes_geos},        {"invalid", c.invalid_ours},
                   {"holes_geos_artifacts", c.holes_geos_artifacts}};
    if (!ok) rc = 3;
  }
  if (!stats_path.empty() && !write_stats(stats_path, result, write_s, index_s, total_s, cpu_s, verify ? &verify_json : nullptr,
                                          options.detail, &w))
    rc = 1;
  // The result's ~10 blocks a building are left to the end of the process, which takes their pages back
  // at once: freeing them one by one took 0.1-0.2 s of a 2.4 s city run (tests/bench/RESULTS.md, "The
  // serial steps around the parallel reading"). Reachable from here, they are no leak to LeakSanitizer.
  static const auto* kept_until_exit = new std::shared_ptr<const PipelineResult>(result_ptr);
  (void)kept_until_exit;
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  std::unique_ptr<Ranks> ranks;
  groundplan::cli::sqlite_without_memory_statistics();  // before GDAL opens any SQLite file (gpkg_slices.h)
  try {
#ifdef GROUNDPLAN_WITH_MPI
    // Only under mpirun: a plain start never initialises MPI (and so behaves as the CLI without MPI).
    if (groundplan::cli::launched_by_mpirun()) ranks = std::make_unique<Ranks>(&argc, &argv);
#endif
    const int rc = run(argc, argv, ranks.get());
    GDALDestroyDriverManager();
    return rc;
  } catch (const std::exception& e) {
#ifdef GROUNDPLAN_WITH_MPI
    // One rank failing ends them all: the others would wait for it forever.
    if (ranks && ranks->size() > 1) ranks->abort(e.what());
#endif
    std::fprintf(stderr, "groundplan: %s\n", e.what());
    return 1;
  }
}

// SPDX-License-Identifier: MIT
#include "report.h"

#include <gdal.h>

#include <algorithm>
#include <cpl_string.h>
#include <cstdio>
#include <fstream>

#include <sys/resource.h>

namespace groundplan::cli {
namespace {

using gis::PipelineResult;

std::size_t count_holes(const PipelineResult& r) {
  std::size_t holes = 0;
  for (const auto& p : r.plans) holes += p.polygon.holes.size();
  return holes;
}

/// --stats "spatial_index": the GeoPackage index packed by the CLI (gpkg_rtree.h); one form for the
/// one-process and the tiled run.
nlohmann::json spatial_index_json(const output::RtreeBuild& index) {
  return {{"tables", index.tables},   {"entries", index.entries},   {"read_s", index.read_s}, {"write_s", index.write_s},
          {"commit_s", index.commit_s}, {"error", index.error}, {"by_gdal", index.by_gdal}};
}

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

}  // namespace

void print_problems(const std::vector<groundplan::Problem>& problems, const std::string& problems_written) {
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

std::size_t count_defects(const std::vector<groundplan::Problem>& problems) {
  std::size_t n = 0;
  for (const auto& p : problems) n += p.code != "NOTE";
  return n;
}

std::string problems_and_notes(const std::vector<groundplan::Problem>& problems) {
  const std::size_t defects = count_defects(problems), notes = problems.size() - defects;
  std::string s = std::to_string(defects) + (defects == 1 ? " problem" : " problems");
  if (notes) s += ", " + std::to_string(notes) + (notes == 1 ? " note" : " notes");
  return s;
}

bool writes_problems(const Ogr2ogrArgs& ogr) {
  return ogr.layer_named && std::any_of(ogr.layers.begin(), ogr.layers.end(),
                                        [](const std::string& l) { return EQUAL(l.c_str(), "problems"); });
}

Progress terminal_progress(const Ogr2ogrArgs& ogr) {
  if (!ogr.progress || ogr.quiet) return {};
  return Progress([](double f, const char* msg) { return GDALTermProgress(f, msg, nullptr) != FALSE; });
}

void say_nothing_usable(const Ogr2ogrArgs& ogr, std::size_t buildings_read, const std::vector<Problem>& problems,
                        GDALDataset* ds) {
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

void print_summary(const PipelineResult& result, const Ogr2ogrArgs& ogr, const LodParams& detail, double total_s,
                   double write_s) {
  if (ogr.quiet) return;
  const std::size_t holes = count_holes(result);
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
  if (detail.any())
    std::printf("groundplan: level of detail (%.2f s): %s\n", result.timings.lod_s,
                lod_summary(detail, result.lod_stats).c_str());
  print_problems(result.problems, writes_problems(ogr) ? ogr.dst : std::string());
}

bool write_stats(const std::string& path, const PipelineResult& result, double write_s, double index_s, double total_s,
                 double cpu_s, const nlohmann::json* verify, const groundplan::LodParams& lod,
                 const WriteOutcome* written) {
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
                  {"xml_streamed", streamed}, {"crs_guessed", rs.crs_guessed}};
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
                  {"files_chunked", r.reading.files_chunked}, {"chunks", r.reading.chunks},
                  {"crs_guessed", r.reading.crs_guessed}};
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

}  // namespace groundplan::cli

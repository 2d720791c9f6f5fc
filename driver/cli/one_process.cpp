// SPDX-License-Identifier: MIT
#include "one_process.h"

#include "ogr_groundplan.h"
#include "open_options.h"

#include "preview.h"
#include "report.h"
#include "timing.h"
#include "write_output.h"

#include <groundplan/gis/geos_reference.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>

namespace groundplan::cli {
namespace {

using gis::PipelineResult;

/// --verify: our plans against GEOS's UnaryUnion of the same footprints, said on stdout; `json` gets --stats
/// "verify". False on a mismatch (exit code 3).
bool verify_with_geos(const PipelineResult& result, const LodParams& detail, nlohmann::json& json) {
  const auto c = groundplan::gis::compare_with_geos(result.footprints, result.plans);
  // The footprints themselves, checked against each building's lowest faces while reading
  // (core/src/footprint/ground_check.h): plans right for wrong footprints are no MATCH.
  std::size_t missing_ground = 0;
  std::string first_missing;
  for (const auto& p : result.problems)
    if (p.code == "FOOTPRINT_MISSES_GROUND" && missing_ground++ == 0) first_missing = p.source_id + ": " + p.reason;
  // With a level of detail the plans differ from the exact union on purpose: what must hold is
  // validity and no overlap; the difference is reported.
  const bool lod = detail.any();
  const bool ok = (lod ? c.invalid_ours == 0 && c.overlapping_ours == 0 : c.matches()) && missing_ground == 0;
  if (lod)
    std::printf("groundplan: verify (level of detail on): %s: %zu invalid plans, %zu overlapping pairs; against "
                "the exact GEOS UnaryUnion: area %.6f m2 vs %.6f m2, symmetric difference %.6g m2 (%.3g%%), %zu vs "
                "%zu polygons, %zu vs %zu holes\n",
                ok ? "VALID" : "INVALID", c.invalid_ours, c.overlapping_ours, c.area_ours, c.area_geos,
                c.symdiff_area, c.area_geos > 0 ? 100 * c.symdiff_area / c.area_geos : 0.0, c.polygons_ours,
                c.polygons_geos, c.holes_ours, c.holes_geos);
  else
    std::printf("groundplan: verify against GEOS UnaryUnion, differences decided exactly against the footprints: "
                "%s (%s)\n",
                c.verdict_line().c_str(), c.summary().c_str());
  if (missing_ground)
    std::printf("groundplan: verify: MISMATCH: %zu footprint%s leave%s out ground the building stands on "
                "(FOOTPRINT_MISSES_GROUND; first %s)\n",
                missing_ground, missing_ground == 1 ? "" : "s", missing_ground == 1 ? "s" : "", first_missing.c_str());
  const char* verdict = lod ? (ok ? "valid" : "invalid")
                        : missing_ground ? "mismatch"
                        : c.verdict() == groundplan::gis::GeosComparison::Verdict::Match ? "match"
                        : c.verdict() == groundplan::gis::GeosComparison::Verdict::MatchGeosDiffers
                            ? "match_geos_differs"
                            : "mismatch";
  json = {{"match", c.matches() && missing_ground == 0}, {"verdict", verdict}, {"footprints_missing_ground", missing_ground},
          {"level_of_detail", lod}, {"valid_and_disjoint", c.invalid_ours == 0 && c.overlapping_ours == 0},
          {"symdiff_area_m2", c.symdiff_area}, {"area_m2", c.area_ours},
          {"area_geos_m2", c.area_geos}, {"polygons", c.polygons_ours},      {"polygons_geos", c.polygons_geos},
          {"holes", c.holes_ours},       {"holes_geos", c.holes_geos},        {"invalid", c.invalid_ours},
          {"holes_geos_artifacts", c.holes_geos_artifacts}, {"holes_geos_dropped", c.holes_geos_dropped},
          {"places_geos_wrong", c.places_geos_wrong},     {"largest_geos_wrong_m2", c.largest_geos_wrong_m2},
          {"places_ours_wrong", c.places_ours_wrong},     {"largest_ours_wrong_m2", c.largest_ours_wrong_m2},
          {"places_ours_below_pitch", c.places_ours_below_pitch}, {"places_undecided", c.places_undecided}};
  if (!c.first_ours_wrong.empty()) json["first_ours_wrong"] = c.first_ours_wrong;
  return ok;
}

}  // namespace

int run_one_process(gis::PipelineOptions options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                    const std::string& preview_path, bool verify) {
  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  const Progress progress = terminal_progress(ogr);
  // A new GeoPackage of many plans is written while the union goes on (streamed_gpkg.h).
  const std::size_t id_chars = writes_dbf(ogr) ? 254 : 0;
  std::unique_ptr<output::StreamedGpkg> streamed = stream_plans(ogr, options, id_chars);
  if (streamed)
    options.plan_feed = [&streamed](const PipelineResult& read) { return streamed->engage(read); };
  // The problems layer asked for is written even when no input can be read.
  options.unreadable_throws = !writes_problems(ogr);
  const auto result_ptr = std::make_shared<const PipelineResult>(groundplan::gis::run_pipeline(options, progress.sub(0, 1)));
  const PipelineResult& result = *result_ptr;

  // Nothing usable (every building a problem, or no building at all): say so and fail, without writing an empty
  // result that would look like success (only the problems layer, where asked for). The problems say why.
  const std::string ds_name = std::string(groundplan::driver::kPrefix) + ogr.src;
  if (result.footprints.empty()) {
    say_nothing_usable(ogr, result.buildings_read, result.problems,
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
  const double total_s = seconds_since(t0), cpu_s = groundplan::gis::process_cpu_seconds() - cpu0;  // before --verify and --preview
  if (!w.ok) {
    std::fprintf(stderr, "groundplan: could not write %s%s\n", ogr.dst.c_str(),
                 w.usage_error ? " (bad ogr2ogr options)" : "");
    return 1;
  }
  if (!w.members_note.empty()) std::fprintf(stderr, "groundplan: note: %s\n", w.members_note.c_str());
  print_summary(result, ogr, options.detail, total_s, w.write_s);

  if (!preview_path.empty()) write_preview_png(result, preview_path);

  int rc = 0;
  nlohmann::json verify_json;
  if (verify && !verify_with_geos(result, options.detail, verify_json)) rc = 3;
  if (!stats_path.empty() && !write_stats(stats_path, result, w.write_s, w.index_s, total_s, cpu_s,
                                          verify ? &verify_json : nullptr, options.detail, &w))
    rc = 1;
  // The result's ~10 blocks a building are left to the end of the process, which takes their pages back
  // at once: freeing them one by one took 0.1-0.2 s of a 2.4 s city run (tests/bench/RESULTS.md, "The
  // serial steps around the parallel reading"). Reachable from here, they are no leak to LeakSanitizer.
  static const auto* kept_until_exit = new std::shared_ptr<const PipelineResult>(result_ptr);
  (void)kept_until_exit;
  return rc;
}

}  // namespace groundplan::cli

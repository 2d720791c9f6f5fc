// SPDX-License-Identifier: MIT
// groundplan: ogr2ogr's syntax with ground plans as the source. Our own flags are taken out here
// (CLI11); everything else goes to GDAL's own ogr2ogr parser (GDALVectorTranslateOptionsNew), so every
// ogr2ogr option behaves as users know it. The run is then tiled (tiled_run.h) or in one process (one_process.h).
#include "ogr_groundplan.h"
#include "gpkg_slices.h"
#include "ogr2ogr_args.h"
#include "one_process.h"
#include "ranks.h"
#include "report.h"
#include "tiled_run.h"

#include <groundplan/error.h>
#include <groundplan/gis/lod_choice.h>
#include <groundplan/gis/pipeline.h>

#include <CLI/CLI.hpp>
#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal.h>

#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace groundplan::cli {
namespace {

/// What the command line asks for.
struct CommandLine {
  gis::PipelineOptions options;
  Ogr2ogrArgs ogr;
  std::string stats_path, preview_path;  // --stats, --preview
  std::string tiles = "auto";            // --tiles
  bool verify = false;                   // --verify
};

/// Our flags (CLI11), then GDAL's general options (--config, --debug, --formats ...), then ogr2ogr's syntax (the
/// destination, the source, the layers and GDAL's ogr2ogr options). An exit code where the command line is answered
/// already (--help, --version, --formats, a usage error); nullopt where there is a run to make. Throws
/// InvalidArgument on a bad value.
std::optional<int> parse_command_line(int argc, char** argv, CommandLine& cl) {
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
  std::string device = "auto", footprints = "auto", origin;
  std::string& stats_path = cl.stats_path;
  std::string& preview_path = cl.preview_path;
  std::string lod = "-1";
  bool& verify = cl.verify;
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
  std::string& tiles = cl.tiles;
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
  cl.ogr = split_ogr2ogr_args(rest);
  Ogr2ogrArgs& ogr = cl.ogr;

  gis::PipelineOptions& options = cl.options;
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
  return std::nullopt;
}

/// The command: its arguments, then the run, tiled or in one process.
int run(int argc, char** argv, Ranks* ranks) {
  CommandLine cl;
  if (const std::optional<int> answered = parse_command_line(argc, argv, cl)) return *answered;
  if (takes_tiled_run(cl.tiles, cl.options, cl.ogr, cl.verify, !cl.preview_path.empty(), rank_count(ranks)))
    return run_tiled(cl.options, cl.ogr, cl.stats_path, terminal_progress(cl.ogr), ranks);
  return run_one_process(cl.options, cl.ogr, cl.stats_path, cl.preview_path, cl.verify);
}

}  // namespace
}  // namespace groundplan::cli

int main(int argc, char** argv) {
  std::unique_ptr<groundplan::cli::Ranks> ranks;
  groundplan::output::sqlite_without_memory_statistics();  // before GDAL opens any SQLite file (gpkg_slices.h)
  try {
#ifdef GROUNDPLAN_WITH_MPI
    // Only under mpirun: a plain start never initialises MPI (and so behaves as the CLI without MPI).
    if (groundplan::cli::launched_by_mpirun()) ranks = std::make_unique<groundplan::cli::Ranks>(&argc, &argv);
#endif
    const int rc = groundplan::cli::run(argc, argv, ranks.get());
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

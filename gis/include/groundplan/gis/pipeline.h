// SPDX-License-Identifier: MIT
#pragma once
// The whole job, file(s) in, ground plans out (DESIGN.md stages 1-6). Shared by the OGR driver and the
// CLI so that both routes give the same plans.
#include <groundplan/gis/crs.h>
#include <groundplan/gis/ogr_input.h>
#include <groundplan/ground_plans.h>
#include <groundplan/level_of_detail.h>
#include <groundplan/progress.h>
#include <groundplan/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace groundplan::gis {

enum class FootprintMode { Auto, GroundSurface, Decompose };
struct PipelineResult;

struct PipelineOptions {
  std::vector<std::string> inputs;  // files or folders (a folder: its CityGML, KML/KMZ, glTF files, sorted by name)
  FootprintMode footprints = FootprintMode::Auto;
  int lod = -1;                     // -1 = the highest LoD each building has
  int lod_refinement = -1;          // CityJSON "2.2": the digit after the point (gis/lod_choice.h); -1 = highest
  std::string s_srs;                // -s_srs / -a_srs, S_SRS= / A_SRS=: the CRS of CityGML/CityJSON coordinates, in
                                    // place of what the files say (srsName, referenceSystem); empty = the files'
  std::string t_srs;                // working CRS as the user names it (EPSG:n, WKT, PROJ string); empty = automatic
  std::string origin;               // "lon,lat[,alt]": where a glTF without georeference or a bare .dae sits; empty = none
  AxisOrder source_axis = AxisOrder::Auto;  // CityGML: axis order of the coordinates when a file breaks its CRS's
                                            // rule (EPSG:4979 written lon,lat): --axis-order, AXIS_ORDER=
  OgrInputOptions ogr_input;        // OGR sources (issue 22): --input-layer, --input-where, --id-field, --group-by ...
  UnionParams union_params;
  LodParams detail;                 // level of detail for simulation (issue 9); default: the exact union
  int threads = 0;                  // threads for every stage: --threads, NUM_THREADS=, GDAL_NUM_THREADS; 0 = all cores
  /// CityGML files are cut into chunks of about this many bytes, read side by side (issue 14): 0 = automatic
  /// (about four chunks a thread, 2-8 MiB; on one thread a file over 64 MiB in 32 MiB chunks, so that each is parsed
  /// in memory, citygml.h dom_max_bytes), < 0 = never. The result is the same either way.
  std::int64_t read_chunk_bytes = 0;
  /// OGR sources are cut into ranges of about this many features, read side by side, one dataset handle each
  /// (issue 22, gis/ogr_ranges.h): 0 = automatic (about four ranges a thread, at least 20000 features; never with
  /// one thread), < 0 = never; read_chunk_bytes < 0 also means never. The result is the same either way.
  std::int64_t read_range_features = 0;
  /// Called once the inputs are read, before the union, with the result so far (footprints, CRS): a feed it returns
  /// is told the plans block by block while the union goes on (ground_plans.h PlanFeed; the CLI writes them
  /// meanwhile). Not called with a level of detail, whose steps change the union's plans. Empty, or null returned:
  /// none.
  std::function<PlanFeed*(const PipelineResult& read)> plan_feed;
  /// No input could be read at all: true throws InputError (the first file's fault); false returns the result,
  /// without footprints, its problems naming every file's fault (the CLI, to write the problems layer asked for).
  bool unreadable_throws = true;
};

/// How the inputs were read (--stats "reading").
struct ReadStats {
  std::size_t files = 0;
  std::size_t threads = 0;          // threads the run used
  std::size_t files_chunked = 0;    // CityGML files read in chunks, OGR sources in feature ranges, side by side
  std::size_t chunks = 0;           // their chunks and ranges
  std::uint64_t bytes = 0;          // bytes of all input files
  /// CityGML files and OGR sources read whole although cutting was allowed, and why (small files are not listed;
  /// OGR sources are, where a flag or the driver rules ranges out).
  std::vector<std::pair<std::string, std::string>> read_whole;
  /// CityGML files (some or all of them) streamed through expat instead of parsed in memory by pugixml (the
  /// faster path, citygml.h dom_max_bytes), and why: too large, another encoding, a DOCTYPE, malformed XML ...
  std::vector<std::pair<std::string, std::string>> xml_streamed;
  /// The working CRS was taken from the first file's first building, and the first file read side by side with
  /// the others (false: it was read before them, or no file needed it: -t_srs, one file).
  bool crs_guessed = false;
};

struct StageTimings {
  // read_s: wall time of reading, georeferencing and the footprints made while reading (files and chunks
  // are read side by side, each making its footprints) less footprints_s: the waits for footprints still
  // being made after a file's last byte (files read whole; summed over them). Wall times, not CPU time
  // (cpu_s is the whole run's CPU time).
  double read_s = 0, footprints_s = 0, blocks_s = 0, union_s = 0;  // union_s: boundary evaluation only
  double lod_s = 0;  // level-of-detail steps (snap, close gaps, simplify, filters)
  double cpu_s = 0;  // CPU time of the process (all threads) during run_pipeline: close to the work done
};

struct PipelineResult {
  std::vector<Footprint> footprints;  // one per building (part) with a usable footprint
  std::vector<GroundPlan> plans;      // members index `footprints`
  std::vector<Problem> problems;      // every building not in a plan, and notes
  std::size_t buildings_read = 0;     // buildings (Building or BuildingPart) met in the inputs: a mesh each, or
                                      // given up by the reader with a Problem (NO_GEOMETRY, TRUNCATED ...)
  std::size_t buildings_dropped = 0;  // of those, the ones with no footprint, each named by a Problem (stage read,
                                      // georeference or footprint): buildings_read = footprints + buildings_dropped
  std::size_t blocks = 0;             // blocks of touching footprints (paper §5)
  std::string raster_backend;         // "cpu" or "cuda"
  std::string crs_wkt;                // working CRS (WKT2), empty when the input has no CRS
  std::string crs_name;               // e.g. "EPSG:25833", for messages
  /// The files the readers opened, sorted, each once: the input files and what they link (a KML's COLLADA models
  /// and NetworkLinks, a glTF's buffers, an OGR source's files). The driver's result cache keys on them.
  std::vector<std::string> files_read;
  StageTimings timings;
  LodStats lod_stats;                 // what the level-of-detail steps changed (all zero when off)
  ReadStats reading;
};

/// Runs read -> footprints -> union. Throws InputError when no input can be read at all (every file
/// unreadable and no footprint from any: a truncated file still gives the buildings before the cut; unless
/// options.unreadable_throws is false), Cancelled
/// when `progress` asks to stop. A bad building is a Problem, not an exception.
PipelineResult run_pipeline(const PipelineOptions& options, const Progress& progress = {});

/// The files `inputs` name (a folder: its input files, sorted by name; a .zip: its city files), as run_pipeline
/// reads them. Throws InputError for a missing input or a folder without input files.
std::vector<std::string> input_files(const std::vector<std::string>& inputs);

/// The inputs a source names as users write it, in the CLI and after `GROUNDPLAN:`: one file or folder, or
/// several separated by commas (a path that exists as written is one input, commas and all; double quotes keep
/// a comma inside one name). Empty names are left out.
std::vector<std::string> input_list(const std::string& source);

/// CPU time of this process so far, all threads (getrusage), in seconds: set beside a wall time, it shows
/// idle or spinning cores (--stats "timings_s"."cpu").
double process_cpu_seconds();

/// Threads a run uses: `requested` when > 0, else all cores (TBB's default concurrency).
std::size_t thread_count(int requested);

const char* to_string(FootprintMode mode);
FootprintMode footprint_mode_from_string(const std::string& s);  // throws InvalidArgument
Device device_from_string(const std::string& s);                 // throws InvalidArgument

/// Named level-of-detail settings (--preset, PRESET=): "none" (the exact union) or "cfd" (simulation
/// meshing; docs/level_of_detail.md says why each value). Throws InvalidArgument for other names.
LodParams lod_preset(const std::string& name);
/// "auto", "east-north" (x = longitude / easting) or "north-east": --axis-order, AXIS_ORDER=. Throws InvalidArgument.
AxisOrder axis_order_from_string(const std::string& s);
/// GDAL's GDAL_NUM_THREADS / NUM_THREADS= form: "ALL_CPUS" or "0" -> 0 (all cores), "N" -> N >= 1.
/// Throws InvalidArgument naming `what` (the option) otherwise.
int threads_from_string(const std::string& s, const std::string& what);
/// "exact" (false) or "raster" (true): --resolution-mode, RESOLUTION_MODE=. Throws InvalidArgument.
bool raster_mode_from_string(const std::string& s);

}  // namespace groundplan::gis

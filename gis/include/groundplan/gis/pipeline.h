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

#include <string>
#include <vector>

namespace groundplan::gis {

enum class FootprintMode { Auto, GroundSurface, Decompose };

struct PipelineOptions {
  std::vector<std::string> inputs;  // files or folders (a folder: its CityGML, KML/KMZ, glTF files, sorted by name)
  FootprintMode footprints = FootprintMode::Auto;
  int lod = -1;                     // -1 = the highest LoD each building has
  std::string t_srs;                // working CRS as the user names it (EPSG:n, WKT, PROJ string); empty = automatic
  std::string origin;               // "lon,lat[,alt]": where a glTF without georeference or a bare .dae sits; empty = none
  AxisOrder source_axis = AxisOrder::Auto;  // CityGML: axis order of the coordinates when a file breaks its CRS's
                                            // rule (EPSG:4979 written lon,lat): --axis-order, AXIS_ORDER=
  OgrInputOptions ogr_input;        // OGR sources (issue 22): --input-layer, --input-where, --id-field, --group-by ...
  UnionParams union_params;
  LodParams detail;                 // level of detail for simulation (issue 9); default: the exact union
};

struct StageTimings {
  // footprints_s: the time footprints added to the run (they are made on the other cores while the
  // file is read; this is what the reader made itself plus the wait after reading), not CPU time.
  double read_s = 0, footprints_s = 0, blocks_s = 0, union_s = 0;  // union_s: boundary evaluation only
  double lod_s = 0;  // level-of-detail steps (snap, close gaps, simplify, filters)
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
  StageTimings timings;
  LodStats lod_stats;                 // what the level-of-detail steps changed (all zero when off)
};

/// Runs read -> footprints -> union. Throws InputError when no input can be read at all (every file
/// unreadable and no footprint from any: a truncated file still gives the buildings before the cut), Cancelled
/// when `progress` asks to stop. A bad building is a Problem, not an exception.
PipelineResult run_pipeline(const PipelineOptions& options, const Progress& progress = {});

const char* to_string(FootprintMode mode);
FootprintMode footprint_mode_from_string(const std::string& s);  // throws InvalidArgument
Device device_from_string(const std::string& s);                 // throws InvalidArgument

/// Named level-of-detail settings (--preset, PRESET=): "none" (the exact union) or "cfd" (simulation
/// meshing; docs/level_of_detail.md says why each value). Throws InvalidArgument for other names.
LodParams lod_preset(const std::string& name);
/// "auto", "east-north" (x = longitude / easting) or "north-east": --axis-order, AXIS_ORDER=. Throws InvalidArgument.
AxisOrder axis_order_from_string(const std::string& s);
/// "exact" (false) or "raster" (true): --resolution-mode, RESOLUTION_MODE=. Throws InvalidArgument.
bool raster_mode_from_string(const std::string& s);

}  // namespace groundplan::gis

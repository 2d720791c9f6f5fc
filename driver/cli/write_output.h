// SPDX-License-Identifier: MIT
#pragma once
// How the CLI writes a dataset of ours: through GDAL's ogr2ogr with the user's options, and where it can, a new
// GeoPackage or CSV file by several writers side by side (gpkg_slices.h, csv_slices.h), a new GeoPackage also while
// the union goes on (streamed_gpkg.h), its spatial index packed afterwards (gpkg_rtree.h).
#include "ogr2ogr_args.h"
#include "ogr_groundplan.h"

#include "gpkg_rtree.h"
#include "streamed_gpkg.h"

#include <groundplan/gis/pipeline.h>

#include <gdal.h>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace groundplan::cli {

struct WriteOutcome {
  bool ok = false;
  int usage_error = FALSE;
  bool own_index = false;
  double write_s = 0, index_s = 0;
  output::RtreeBuild built;
  std::string members_note;
  nlohmann::json writer;  // --stats "writer": how many writers, and why one (gpkg_slices.h)
};

/// Runs GDAL's ogr2ogr on `src` with `args`; false (GDAL has printed why) on failure.
bool vector_translate(const std::string& dst, GDALDatasetH src, const std::vector<std::string>& args, bool progress,
                      int* usage_error);

using AnotherDataset = std::function<groundplan::driver::OGRGroundPlanDataSource*(int threads)>;

/// The writer of a new GeoPackage that starts while the union goes on (streamed_gpkg.h), or null where the plans are
/// written after the union: not a new GeoPackage whose index the CLI packs, an ogr2ogr option that rules slices out
/// (gpkg_slices.h), a level of detail (its steps change the union's plans), one thread, or
/// `--config GROUNDPLAN_WRITE_DURING_UNION NO`. Whether it is used is known once the union has begun (enough plans).
std::unique_ptr<output::StreamedGpkg> stream_plans(const Ogr2ogrArgs& ogr, const gis::PipelineOptions& options,
                                           std::size_t id_chars);

/// Writes our dataset (taking it: closed here) through GDAL's ogr2ogr with the user's options, packs a new
/// GeoPackage's spatial index, and writes the full member lists beside a DBF whose id lists were cut.
/// `another`, where given, makes one more dataset like `ds` (the one-process result): a new GeoPackage is then
/// written by several writers side by side (gpkg_slices.h).
WriteOutcome write_output(driver::OGRGroundPlanDataSource* ds, const Ogr2ogrArgs& ogr, int threads,
                          const AnotherDataset& another = {}, output::StreamedGpkg* streamed = nullptr);

}  // namespace groundplan::cli

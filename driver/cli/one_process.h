// SPDX-License-Identifier: MIT
#pragma once
// The run in one process (gis/pipeline.h): every footprint read, united at once, then written (write_output.h),
// a new GeoPackage of many plans while the union goes on; --preview and --verify look at the whole result.
#include "ogr2ogr_args.h"

#include <groundplan/gis/pipeline.h>

#include <string>

namespace groundplan::cli {

/// Reads, unites and writes; says what it did (report.h). Returns the process's exit code: 1 when nothing usable was
/// read or the write failed, 3 when --verify found a mismatch.
int run_one_process(gis::PipelineOptions options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                    const std::string& preview_path, bool verify);

}  // namespace groundplan::cli

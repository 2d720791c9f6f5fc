// SPDX-License-Identifier: MIT
#pragma once
// The tiled run (gis/tiled.h): the input files mapped one tile at a time with bounded memory, the plans crossing
// tile edges united at the end; in one process, or shared by the ranks of `mpirun -np N` (rank_runs.h, through the
// MPI exchange, mpi_exchange.h).
#include "ogr2ogr_args.h"
#include "ranks.h"

#include <groundplan/gis/pipeline.h>
#include <groundplan/progress.h>

#include <string>

namespace groundplan::cli {

/// Whether the run is tiled: `tiles` (--tiles) on, or auto where it pays off (tiles_pay_off in the .cpp); always
/// under mpirun with several ranks. Throws InvalidArgument where `tiles` is not auto, on or off, or where the tiled
/// run is asked for (--tiles on, or by mpirun) but cannot give what was asked for (`verify`, a `preview` ...).
bool takes_tiled_run(const std::string& tiles, const gis::PipelineOptions& options, const Ogr2ogrArgs& ogr,
                     bool verify, bool preview, int ranks);

/// The tiled run (issue 15, gis/tiled.h): same plans with bounded memory; the final plans of all tiles first,
/// then the plans from seams. --stats says how many were final at once and how many were seams.
int run_tiled(const gis::PipelineOptions& options, const Ogr2ogrArgs& ogr_in, const std::string& stats_path,
              const Progress& progress, Ranks* ranks);

}  // namespace groundplan::cli

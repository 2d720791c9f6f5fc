// SPDX-License-Identifier: MIT
#pragma once
// The tiled run shared by the ranks of `mpirun -np N groundplan` (an MPI build) where every rank writes its own final
// plans: into PostgreSQL (rank_writes.h) or into a new GeoPackage, a slice each (gpkg_rank_slices.h). Other outputs
// are written by rank 0 alone (tiled_run.h).
#include "ogr2ogr_args.h"
#include "ranks.h"

#include <groundplan/gis/pipeline.h>
#include <groundplan/progress.h>

#include <string>

namespace groundplan::cli {

/// The tiled run over ranks into PostgreSQL (issue 15 stage 5, rank_writes.h): every rank writes its own final
/// plans into the tables rank 0 makes, each in a transaction committed once all have written.
int run_tiled_into_database(const gis::PipelineOptions& options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                            const Progress& progress, Ranks& ranks);

/// Under mpirun into a file: why rank 0 writes every plan (gathered to it), rather than every rank its own into a
/// GeoPackage slice (gpkg_rank_slices.h); empty: every rank writes. Collective, before the run (the ranks keep
/// their plans or stream them). Rank 0 decides: a new local GeoPackage whose index the CLI packs, and ogr2ogr
/// options that act on each feature alone (gpkg_slices.h slices_ruled_out); then it leaves a file with a token
/// beside the destination, which every rank must read back: the slices go into that folder, so a rank on a host
/// that does not share it (no shared file system) would write where rank 0 cannot read.
std::string why_rank_0_writes(const Ogr2ogrArgs& ogr, Ranks& ranks);

/// The tiled run over ranks into a new GeoPackage (gpkg_rank_slices.h): every rank writes its own final plans into a
/// slice beside rank 0's staged destination, side by side; rank 0 appends the slices in FID order, packs the
/// spatial index, and moves the file into place once every rank has finished.
int run_tiled_gpkg_by_ranks(const gis::PipelineOptions& options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                            const Progress& progress, Ranks& ranks);

}  // namespace groundplan::cli

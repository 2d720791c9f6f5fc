// SPDX-License-Identifier: MIT
#pragma once
// What a run says: its summary and problems on the terminal, and --stats (counts and per-stage timings as JSON),
// for the one-process and the tiled run.
#include "ogr2ogr_args.h"
#include "write_output.h"

#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/tiled.h>
#include <groundplan/progress.h>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace groundplan::cli {

/// The first problems on stderr, and how many more there are.
void print_problems(const std::vector<Problem>& problems);

/// Problems proper, without notes (a CRS guess is worth saying but is no defect).
std::size_t count_defects(const std::vector<Problem>& problems);

/// -progress: GDAL's progress bar on the terminal, unless -q; otherwise none.
Progress terminal_progress(const Ogr2ogrArgs& ogr);

/// A run without a footprint (every building a problem, or none at all): its problems (unless -q) and why nothing is
/// written.
void say_nothing_usable(const Ogr2ogrArgs& ogr, std::size_t buildings_read, const std::vector<Problem>& problems);

/// What the one-process run says when it has written (unless -q): counts, timings, the level of detail, problems.
void print_summary(const gis::PipelineResult& result, const Ogr2ogrArgs& ogr, const LodParams& detail, double total_s,
                   double write_s);

/// --stats of the one-process run: counts (buildings = footprints + dropped: nothing lost) and per-stage timings,
/// "verify" where given, the writer and spatial index where `written`. False (said on stderr) when the file cannot be
/// written.
bool write_stats(const std::string& path, const gis::PipelineResult& result, double write_s, double index_s,
                 double total_s, double cpu_s, const nlohmann::json* verify, const LodParams& lod,
                 const WriteOutcome* written = nullptr);

/// --stats of a tiled run (one process or ranks): counts, timings, "tiles", "mpi". `plans`: in the whole dataset
/// (rank 0 of a run whose ranks write their own plans holds none of theirs). Nothing where `stats_path` is empty;
/// false (said) when it cannot be written.
bool write_tiled_stats(const std::string& stats_path, const gis::TiledResult& r, std::size_t plans, double write_s,
                       double index_s, const WriteOutcome* written, double total_s, double cpu_s);

/// What a tiled run says when it has written (unless -q): counts, the tiles' share, timings, problems.
void print_tiled_summary(const gis::TiledResult& r, const Ogr2ogrArgs& ogr, const std::string& dst, std::size_t plans,
                         double total_s, double write_s);

}  // namespace groundplan::cli

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

/// The first problems and notes on stderr, and how many of each are not shown (counted as the summary counts:
/// problems apart from notes). `problems_written`: the dataset whose problems layer holds them all; empty when no
/// problems layer was written.
void print_problems(const std::vector<Problem>& problems, const std::string& problems_written = {});

/// Problems proper, without notes (a CRS guess is worth saying but is no defect).
std::size_t count_defects(const std::vector<Problem>& problems);

/// "4 problems" or "4 problems, 36 notes": the summary's count, notes apart.
std::string problems_and_notes(const std::vector<Problem>& problems);

/// Whether the output holds a problems layer (named among the layers written).
bool writes_problems(const Ogr2ogrArgs& ogr);

/// -progress: GDAL's progress bar on the terminal, unless -q; otherwise none.
Progress terminal_progress(const Ogr2ogrArgs& ogr);

/// A run without a footprint (every building a problem, or none at all): the problems layer alone is written where it
/// was asked for (through `ds`, taken and closed here; null: nothing is written, as a rank of a run over ranks does),
/// no empty ground plans that would look like a result; the problems (unless -q) and why nothing else is written go
/// to stderr. The run fails all the same.
void say_nothing_usable(const Ogr2ogrArgs& ogr, std::size_t buildings_read, const std::vector<Problem>& problems,
                        GDALDataset* ds = nullptr);

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

// SPDX-License-Identifier: MIT
#pragma once
// The optional cache of pipeline results across processes (issue 18): GROUNDPLAN_CACHE_DIR=<folder> (a GDAL
// configuration option; unset: off). One file per key, named by a hash of it, holding the whole key: a file
// is used only when the key it holds is the key asked for (a hash collision or a changed input is a miss),
// and only when it reads back whole. Files are written to a temporary name and renamed into place, so a
// reader never sees half a file, and two processes writing the same key leave one whole file.
//
// The key (result_cache.h) holds the inputs' sizes, times and inodes, so a changed input is a new key:
// the old file is never read again (nothing removes it; clear the folder to reclaim the space). It also
// holds this build's identity, so results of another build of the pipeline are never used. The files the
// inputs link (models, buffers) are stored with their stamps beside the key: a changed one makes it a miss.
//
// Stored: what the driver's layers show (footprints, plans, problems, the working CRS, the counts of
// buildings read and dropped, blocks, backend); the timings and reading statistics are not (they describe
// the run that made the result, and the driver shows neither).
#include <groundplan/gis/pipeline.h>

#include <optional>
#include <string>

namespace groundplan::driver {

/// The folder GROUNDPLAN_CACHE_DIR names, or "" when the persistent cache is off.
std::string result_store_dir();

/// The result stored for `key` in `dir`; nothing when there is none, it holds another key or cannot be read.
/// `stamps` gets the stamps of the files it was read from, as stored with it.
std::optional<gis::PipelineResult> load_result(const std::string& dir, const std::string& key, std::string* stamps);

/// Stores `result` for `key` in `dir` (created if needed), with `stamps`, the stamps of the files it was read from
/// (result_cache.cpp): a later process uses it only while they are unchanged. False, with a CPLDebug line saying
/// why, on failure.
bool store_result(const std::string& dir, const std::string& key, const gis::PipelineResult& result,
                  const std::string& stamps);

}  // namespace groundplan::driver

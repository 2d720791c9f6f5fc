// SPDX-License-Identifier: MIT
#pragma once
// Pipeline results shared by every GROUNDPLAN: dataset one process opens (issue 18). QGIS opens a layer's
// source several times (the layer, its feature iterators, render threads, the attribute table), ogrinfo opens
// it once per layer listed and Python scripts open it in loops: each open of the same input with the same
// options gets the result the first open computed.
//
// The key: every input's canonical path and the size, modification and change times and inode of every file
// it names (a file; a folder: its input files, gis::input_files), plus every open option except NUM_THREADS
// (the result is the same with any thread count). A result is reused only while the files the readers opened
// for it (PipelineResult::files_read: the inputs and what they link, a KML's COLLADA models and NetworkLinks, a
// glTF's buffers, an OGR source's sidecars; also those looked for and missing) have the stamps they had when it
// was made: a changed linked file computes again, while a file written beside the input that no reader opens
// (the output GeoPackage, a log) changes nothing. An input that is not a local file or folder (a database
// connection, /vsicurl/ ...) or a folder of more than kMaxTrackedFiles input files is not cached: every open
// computes.
//
// Bounds: a result stays while any dataset holds it (open datasets share it, at no cost), and the last
// GROUNDPLAN_CACHE_ENTRIES results (default 4) closed datasets left are kept while their estimated size is
// within GROUNDPLAN_CACHE_MAX_MB (default 1024); older ones are dropped first. GROUNDPLAN_CACHE=NO turns
// the cache off. These are GDAL configuration options (environment variables or --config).
// GROUNDPLAN_CACHE_DIR=<folder> adds a cache across processes (result_store.h; off by default). The key also
// names the build of the code (the plugin's file and stamp), so another build never reads this one's results.
//
// Thread-safe: two opens of one key at once compute once, the second waits for the first; a failure
// reaches both and is not kept. CPL_DEBUG=ON shows "GroundPlan: pipeline run N for <connection>" for every
// computation, "GroundPlan: cached result for <connection>" for every hit in the process and "GroundPlan:
// result for <connection> read from <folder>" for every hit in GROUNDPLAN_CACHE_DIR.
#include <groundplan/gis/pipeline.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace groundplan::driver {

using SharedResult = std::shared_ptr<const gis::PipelineResult>;

/// Input files beyond this many in one input folder: the input is not cached (its key would take too long).
inline constexpr std::size_t kMaxTrackedFiles = 20000;

/// The key of an open of `inputs` with the CSL open options `open_options`; empty when not cacheable.
std::string result_cache_key(const std::vector<std::string>& inputs, char** open_options);

/// The result of `key`, computed by `compute` when the cache has none (always, when `key` is empty).
/// `what` names the open in debug messages (the connection string). Rethrows what `compute` throws.
SharedResult cached_pipeline_result(const std::string& key, const std::string& what,
                                    const std::function<gis::PipelineResult()>& compute);

/// Pipeline runs cached_pipeline_result started in this process so far.
std::size_t pipeline_runs();

/// Approximate memory a result holds, in bytes (the cache's bound counts it).
std::size_t result_bytes(const gis::PipelineResult& result);

}  // namespace groundplan::driver

// SPDX-License-Identifier: MIT
#pragma once
// The pieces of run_pipeline that the tiled run (tiled.cpp) shares: which files the inputs name, their size,
// and how one file's reading joins the result (working CRS fixed by the first georeferenced file).
#include <groundplan/gis/pipeline.h>

#include "pipeline/file_reading.h"

#include <cstdint>
#include <string>
#include <vector>

namespace groundplan::gis::detail {

/// Files named by the inputs: a file as is, a folder as its input files sorted by name, a .zip as its city
/// files. Throws InputError for a missing input or a folder without input files.
std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs, std::vector<Problem>& problems);

/// Bytes of all `files` (those that can be stat'ed).
std::uint64_t total_bytes(const std::vector<std::string>& files);

/// Adds one file's outcome to `result`, in file order (footprints, problems, counts), and fixes the working CRS
/// from it the way reading the files one after the other does: the first georeferenced file decides (or -t_srs).
void merge_file(FileRead&& r, const std::string& file, ReadContext& context, PipelineResult& result,
                std::size_t& files_failed, std::string& first_failure);

/// merge_file's CRS part: what one file's reading, in file order, fixes of the working CRS (context) and of the
/// result's CRS.
void fix_crs(const FileRead& r, const std::string& file, ReadContext& context, PipelineResult& result);

/// Whether the first file's reading fixed the working CRS that guess_working_definition guessed from it, where the
/// later files were read side by side with it in that CRS.
bool guess_held(const FileRead& first, const std::string& file, const ReadContext& before, const std::string& guess);

}  // namespace groundplan::gis::detail

// SPDX-License-Identifier: MIT
#pragma once
#include <groundplan/gis/pipeline.h>

#include <string>

namespace groundplan::cli {

/// Writes a PNG map of the plans (filled, holes left open, rings outlined) with the footprints of
/// buildings that have a problem in red, `max_side_px` on the long side. Throws Error on failure.
void write_preview_png(const gis::PipelineResult& result, const std::string& path, int max_side_px = 1600);

}  // namespace groundplan::cli

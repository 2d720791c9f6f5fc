// SPDX-License-Identifier: MIT
#pragma once
// Open options of the GroundPlan driver and their mapping to PipelineOptions. The CLI turns its own
// flags into the same open options, so both routes read settings in one place.
#include <groundplan/gis/pipeline.h>

#include <string>

namespace groundplan::driver {

inline constexpr const char* kPrefix = "GROUNDPLAN:";

/// The XML GDAL shows in `ogrinfo --format GroundPlan` (GDAL_DMD_OPENOPTIONLIST).
const char* open_option_list_xml();

/// Reads RESOLUTION, DEVICE, FOOTPRINTS, LOD, T_SRS, ORIGIN and the level-of-detail options (PRESET first,
/// then RESOLUTION_MODE, SNAP, CLOSE_GAPS, MIN_HOLE_AREA, MIN_AREA, SIMPLIFY override it) from a CSL list (char**). Throws InvalidArgument
/// naming the option and the bad value.
gis::PipelineOptions pipeline_options_from(const std::string& connection, char** open_options);

/// "GROUNDPLAN:a.gml,b.gml" -> {"a.gml","b.gml"}; throws InvalidArgument without the prefix.
std::vector<std::string> inputs_from_connection(const std::string& connection);

}  // namespace groundplan::driver

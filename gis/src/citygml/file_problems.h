// SPDX-License-Identifier: MIT
#pragma once
// The problems a CityGML reader says once per file, at its end (whole-file and chunked reads alike).
#include <groundplan/gis/citygml.h>

#include <string>
#include <vector>

namespace groundplan::gis::detail {

/// NOT_CITYGML when no CityGML namespace was met, MIXED_SRS when two srsNames were.
void add_file_problems(const SourceInfo& info, const std::string& name, std::vector<Problem>& problems);

}  // namespace groundplan::gis::detail

// SPDX-License-Identifier: MIT
#pragma once
// Small helpers shared by the C++ tests.
#include <groundplan/types.h>

#include <string>
#include <vector>

namespace groundplan::test {

/// Path of a file under ../shared/data (read-only third-party samples; CI reads them in place).
std::string shared_data(const std::string& relative);
/// Path of a file under sample_data/.
std::string sample_data(const std::string& relative);

/// Footprints from WKT polygons, one footprint per string, ids "f0", "f1", ...
std::vector<Footprint> footprints_from_wkt(const std::vector<std::string>& wkts);

}  // namespace groundplan::test

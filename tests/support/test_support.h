// SPDX-License-Identifier: MIT
#pragma once
// Small helpers shared by the C++ tests.
#include <groundplan/mesh.h>
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

/// A copy of `m` without its GroundSurface faces (so that decomposition cannot use them).
Mesh without_ground(const Mesh& m);

}  // namespace groundplan::test

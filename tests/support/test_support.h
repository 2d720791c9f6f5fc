// SPDX-License-Identifier: MIT
#pragma once
// Small helpers shared by the C++ tests.
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <filesystem>
#include <string>
#include <vector>

#include "real_samples.h"  // sample_data, shared_data: where the real city models are

namespace groundplan::test {

/// Footprints from WKT polygons, one footprint per string, ids "f0", "f1", ...
std::vector<Footprint> footprints_from_wkt(const std::vector<std::string>& wkts);

/// A folder under the system temp folder, removed with everything in it when this goes out of scope.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& prefix = "groundplan_test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// Writes `content` to `rel` (folders made as needed); returns the file's path.
  std::string file(const std::string& rel, const std::string& content) const;
};

/// Each plan as "x y,x y,...|holes" (outer ring, 6 decimals), sorted: plans compared as a set.
std::vector<std::string> plan_keys(const std::vector<GroundPlan>& plans);

/// A copy of `m` without its GroundSurface faces (so that decomposition cannot use them).
Mesh without_ground(const Mesh& m);

}  // namespace groundplan::test

// SPDX-License-Identifier: MIT
// The level-of-detail steps (issue 9) on random polygon sets: bytes 0-1 pick the settings (snap,
// close gaps, simplify, min hole area, min area, raster mode, each with a few values scaled to the
// coordinates), the rest are footprints as for the union target (fuzz_polygons.h). Checked:
//   - no exception but groundplan::Error;
//   - every plan valid by GEOS and no two plans overlapping (the 100% requirement);
//   - nothing lost: every footprint is a member of a plan or named by a union or lod problem.
#include "fuzz_entry.h"
#include "fuzz_polygons.h"

#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/level_of_detail.h>

#include <set>
#include <string>
#include <vector>

GROUNDPLAN_FUZZ_TARGET(lod) {
  using namespace groundplan;
  if (size < 3) return 0;
  const std::uint8_t a = data[0], b = data[1];
  std::vector<Footprint> fps = fuzz::decode_footprints(data + 2, size - 2);
  if (fps.empty()) return 0;
  // Lengths relative to the decoded grid (coordinates step 1, 0.125, 0.5 or 1/7).
  static const double lengths[] = {0, 1e-3, 0.05, 0.3, 1.0, 2.5};
  LodParams lod;
  lod.snap_m = lengths[a % 6];
  lod.close_gaps_m = lengths[(a / 6) % 6];
  lod.simplify_m = lengths[(a / 36) % 6];
  lod.min_hole_area_m2 = (b & 1) ? 0.5 : 0;
  lod.min_area_m2 = (b & 2) ? 0.5 : 0;
  lod.raster = b & 4;
  UnionParams params;
  params.device = Device::Cpu;
  params.resolution_m = (b & 8) ? 0.5 : 0;
  std::vector<Problem> problems;
  std::vector<GroundPlan> plans;
  try {
    plans = build_ground_plans(fps, params, lod, problems, {}, nullptr);
  } catch (const Error&) {
    return 0;  // a refusal with a message is an answer
  }
  std::vector<bool> member(fps.size(), false);
  for (const GroundPlan& gp : plans)
    for (std::uint32_t m : gp.members) {
      if (m >= fps.size()) groundplan_fuzz_fail("lod", "a plan member index is out of range");
      member[m] = true;
    }
  std::set<std::string> named;
  for (const Problem& p : problems)
    if (p.stage == "union" || p.stage == "lod") {
      // a hole or plan problem may name several buildings: "a, b (+N more)"
      std::string s = p.source_id;
      std::size_t start = 0;
      while (start <= s.size()) {
        const std::size_t comma = s.find(", ", start);
        named.insert(s.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 2;
      }
    }
  for (std::size_t i = 0; i < fps.size(); ++i)
    if (!member[i] && !named.count(fps[i].source_id))
      groundplan_fuzz_fail("lod", ("footprint " + fps[i].source_id + " is in no plan and named by no problem").c_str());
  const gis::GeosComparison c = gis::compare_with_geos(fps, plans);
  if (c.invalid_ours) groundplan_fuzz_fail("lod", ("invalid plan: " + c.first_invalid_reason).c_str());
  if (c.overlapping_ours) groundplan_fuzz_fail("lod", "two plans overlap");
  return 0;
}

// SPDX-License-Identifier: MIT
// Footprints the union refuses, each named by a Problem (union/input_check.h, issue 20).
#include "union/input_check.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "robust/coordinate_range.h"
#include "robust/predicates.h"

namespace groundplan::detail {
namespace {

/// Where the first inadmissible coordinate is, or an empty code when there is none.
struct Defect {
  std::string code, reason;
};

Defect first_bad_coordinate(const Footprint& f) {
  for (std::size_t pi = 0; pi < f.polygons.size(); ++pi) {
    const Polygon& p = f.polygons[pi];
    for (std::size_t ri = 0; ri <= p.holes.size(); ++ri) {
      const Ring& r = ri == 0 ? p.outer : p.holes[ri - 1];
      for (std::size_t vi = 0; vi < r.size(); ++vi) {
        if (robust::admissible(r[vi])) continue;
        const bool bad_x = !robust::admissible(r[vi].x);
        const double v = bad_x ? r[vi].x : r[vi].y;
        char where[160];
        std::snprintf(where, sizeof where, "polygon %zu, %s, vertex %zu has %c = %.17g", pi + 1,
                      ri == 0 ? "outer ring" : ("hole " + std::to_string(ri)).c_str(), vi + 1, bad_x ? 'x' : 'y', v);
        if (!std::isfinite(v))
          return {"NOT_FINITE", std::string(where) + " (NaN or infinite): the footprint is not in any plan"};
        return {"COORDINATE_OUT_OF_RANGE",
                std::string(where) + ": coordinates must be 0 or of magnitude between 2^-150 and 2^50 (~1.1e15 m) "
                                     "for exact arithmetic; the footprint is not in any plan"};
      }
    }
  }
  return {};
}

/// True if some ring of some polygon has three non-collinear vertices (exact): the even-odd region
/// can only have area then. Coordinates are admissible here.
bool has_area(const Footprint& f) {
  auto ring = [](const Ring& r) {
    if (r.size() < 3) return false;
    std::size_t i1 = 1;
    while (i1 < r.size() && r[i1] == r[0]) ++i1;
    for (std::size_t i = i1 + 1; i < r.size(); ++i)
      if (robust::orient(r[0], r[i1], r[i]) != 0) return true;
    return false;
  };
  for (const Polygon& p : f.polygons) {
    if (ring(p.outer)) return true;
    for (const Ring& h : p.holes)
      if (ring(h)) return true;
  }
  return false;
}

}  // namespace

bool coordinates_admissible(const Footprint& footprint) { return first_bad_coordinate(footprint).code.empty(); }

std::vector<char> usable_footprints(const std::vector<Footprint>& footprints, std::vector<Problem>& problems) {
  std::vector<char> usable(footprints.size(), 0);
  // Checked side by side (in the caller's arena); the few refused are named in order after.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, footprints.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      usable[i] = coordinates_admissible(footprints[i]) && has_area(footprints[i]);
  });
  for (std::size_t i = 0; i < footprints.size(); ++i) {
    if (usable[i]) continue;
    const Footprint& f = footprints[i];
    Defect d = first_bad_coordinate(f);
    if (d.code.empty()) d = {"NO_AREA", "the footprint has no area (fewer than three non-collinear points): not in any plan"};
    problems.push_back(Problem{f.source_id, f.source_file, "union", std::move(d.code), std::move(d.reason)});
  }
  return usable;
}

}  // namespace groundplan::detail

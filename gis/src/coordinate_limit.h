// SPDX-License-Identifier: MIT
#pragma once
// The readers' limit on coordinates as written (CityGmlOptions, CityJsonOptions, OgrInputOptions::
// max_abs_coordinate, 1e9 by default), said the same way by each: a polygon or feature past it is
// COORDINATE_OUT_OF_RANGE. The union's own, wider limit (2^50 m, core/src/robust/coordinate_range.h) only
// meets footprints given to libgroundplan directly.
#include <cstdio>
#include <string>

namespace groundplan::gis {

/// "a coordinate lies beyond the readers' limit of ±1e+09 (...)" for a coordinate past `limit`.
inline std::string beyond_coordinate_limit(double limit) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "a coordinate lies beyond the readers' limit of ±%.6g", limit);
  return std::string(buf) + " (no CRS on Earth goes past 1e9, in metres or degrees)";
}
/// The same naming the value `v`: "the coordinate 3.3e+12 lies beyond ...".
inline std::string beyond_coordinate_limit(double v, double limit) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "the coordinate %.6g", v);
  return buf + beyond_coordinate_limit(limit).substr(std::string("a coordinate").size());
}

}  // namespace groundplan::gis

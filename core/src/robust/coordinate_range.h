// SPDX-License-Identifier: MIT
#pragma once
// The coordinates the exact predicates are certified for (issue 20). The error bounds of
// predicates.h assume that no product of coordinate differences overflows and that none
// underflows into the subnormal range (Shewchuk's filter and two_prod are exact only there), and
// the raster's pixel indices assume finite extents. Both hold for every coordinate that is 0 or
// has a magnitude in [kMinAbsCoordinate, kMaxAbsCoordinate]:
//   - the largest difference is 2^51, and degree-4 expressions of differences stay below 2^210;
//   - nonzero coordinates are multiples of 2^(-150-52), so a nonzero difference is at least
//     2^-202 and a degree-4 product at least 2^-808, with its rounding error term (2^-106 of
//     it) still a normal double (> 2^-1022).
// 2^50 m is ~1.1e15 m, beyond any position on Earth in any CRS; 2^-150 m is ~7e-46 m. A footprint
// with any other coordinate (NaN, ±inf, ±1e300, subnormals) is refused with a Problem, never
// computed with.
#include <groundplan/types.h>

#include <cmath>

namespace groundplan::robust {

inline constexpr double kMaxAbsCoordinate = 0x1p50;
inline constexpr double kMinAbsCoordinate = 0x1p-150;

/// True when v may be used by the predicates: 0, or a magnitude within the range above. NaN is not.
inline bool admissible(double v) {
  const double a = std::fabs(v);
  return a == 0 || (a >= kMinAbsCoordinate && a <= kMaxAbsCoordinate);
}
inline bool admissible(const Point2& p) { return admissible(p.x) && admissible(p.y); }

}  // namespace groundplan::robust

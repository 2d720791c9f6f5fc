// SPDX-License-Identifier: MIT
#pragma once
// Small ring measures shared by the level-of-detail steps (core/src/lod).
#include <groundplan/types.h>

#include <algorithm>
#include <cstddef>

namespace groundplan::lod {

/// Twice the signed area of a ring (positive: counter-clockwise), about its first vertex: at UTM
/// magnitudes the differences are exact and the sum keeps the digits of small rings.
inline long double ring_area2(const Ring& r) {
  if (r.size() < 3) return 0;
  const Point2 o = r[0];
  long double s = 0;
  for (std::size_t i = 1; i + 1 < r.size(); ++i)
    s += static_cast<long double>(r[i].x - o.x) * (r[i + 1].y - o.y) -
         static_cast<long double>(r[i + 1].x - o.x) * (r[i].y - o.y);
  return s;
}

/// Squared distance from p to the closed segment a-b (double: tolerance decisions, not topology).
inline double segment_distance2(const Point2& p, const Point2& a, const Point2& b) {
  const double ux = b.x - a.x, uy = b.y - a.y;
  const double wx = p.x - a.x, wy = p.y - a.y;
  const double len2 = ux * ux + uy * uy;
  double t = len2 > 0 ? (wx * ux + wy * uy) / len2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  const double dx = wx - t * ux, dy = wy - t * uy;
  return dx * dx + dy * dy;
}

}  // namespace groundplan::lod

// SPDX-License-Identifier: MIT
// Differences against GEOS that are features narrower than the snap pitch (see below_pitch.h).
#include "below_pitch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geos_handles.h"

namespace groundplan::gis::detail {

bool narrower_than(GEOSContextHandle_t h, const GEOSGeometry* piece, double w) {
  double area = 0, perimeter = 0;
  GEOSArea_r(h, piece, &area);
  GEOSLength_r(h, piece, &perimeter);
  if (perimeter > 0 && 2 * area / perimeter <= w / 2) return true;
  const GeomPtr left(GEOSBuffer_r(h, piece, -w / 2, 8), GeomDeleter{h});
  return left && GEOSisEmpty_r(h, left.get()) == 1;
}

BelowPitch differences_below_pitch(const std::vector<Polygon>& ours, const std::vector<Polygon>& geos, double pitch) {
  // A local origin: coordinates of 1e6 m have ulps of 1e-10 m, too coarse for a buffer of 1e-8 m. The shift is
  // an integer no larger than the coordinates, so it is exact for coordinates of the same sign and binade.
  double minx = INFINITY, miny = INFINITY, maxabs = 0;
  for (const auto* side : {&ours, &geos})
    for (const Polygon& p : *side)
      for (const Point2& q : p.outer) {
        minx = std::min(minx, q.x);
        miny = std::min(miny, q.y);
        maxabs = std::max({maxabs, std::fabs(q.x), std::fabs(q.y)});
      }
  const Point2 o = maxabs > 1024 && std::isfinite(minx) ? Point2{std::floor(minx), std::floor(miny)} : Point2{0, 0};
  Context ctx;
  const GEOSContextHandle_t h = ctx.get();
  auto moved = [&](const Ring& r) {
    Ring m;
    m.reserve(r.size());
    for (const Point2& q : r) m.push_back({q.x - o.x, q.y - o.y});
    return m;
  };
  auto all = [&](const std::vector<Polygon>& ps) {
    std::vector<GEOSGeometry*> parts;
    for (const Polygon& p : ps) {
      Polygon m;
      m.outer = moved(p.outer);
      for (const Ring& r : p.holes) m.holes.push_back(moved(r));
      if (GEOSGeometry* g = make_polygon(h, m)) parts.push_back(g);
    }
    GeomPtr c(GEOSGeom_createCollection_r(h, GEOS_GEOMETRYCOLLECTION, parts.data(), static_cast<unsigned>(parts.size())),
              GeomDeleter{h});
    return GeomPtr(c ? GEOSUnaryUnion_r(h, c.get()) : nullptr, GeomDeleter{h});
  };
  BelowPitch out;
  const double w = 1.5 * pitch;
  const GeomPtr a = all(ours), b = all(geos);
  const GeomPtr d(a && b ? GEOSSymDifference_r(h, a.get(), b.get()) : nullptr, GeomDeleter{h});
  if (!d) {
    out.all = false;
    out.first_not = "GEOS could not compute the symmetric difference";
    return out;
  }
  // Piece by piece: narrower than w if shrinking it by w/2 leaves nothing, or if twice its area over its
  // perimeter (its width, for a sliver) is at most w/2. The second test is for slivers a few ulps wide,
  // where GEOS's buffer is not exact enough to erase them; a piece wider than w somewhere passes it only
  // if a strand of the data's whole extent hangs off a blob well under a micrometre across.
  std::vector<const GEOSGeometry*> pieces;
  collect_polygons(h, d.get(), pieces);
  const GEOSGeometry* wide = nullptr;
  for (const GEOSGeometry* piece : pieces) {
    if (narrower_than(h, piece, w)) continue;
    wide = piece;
    break;
  }
  if (!wide) return out;
  out.all = false;
  double x = 0, y = 0;
  if (GeomPtr c{GEOSGetCentroid_r(h, wide), GeomDeleter{h}}) {
    GEOSGeomGetX_r(h, c.get(), &x);
    GEOSGeomGetY_r(h, c.get(), &y);
  }
  char buf[160];
  std::snprintf(buf, sizeof buf, "the plans and GEOS's union differ by more than %.3g m wide near (%.9g %.9g)", w,
                x + o.x, y + o.y);
  out.first_not = buf;
  return out;
}

}  // namespace groundplan::gis::detail

// SPDX-License-Identifier: MIT
#pragma once
// GEOS through its C API for the reference (geos_reference.cpp) and the check of count differences
// (below_pitch.cpp): one context per object, owning pointers, our rings and polygons to and from GEOS.
#include <groundplan/types.h>

#include <geos_c.h>

#include <memory>
#include <vector>

namespace groundplan::gis::detail {

inline void geos_message(const char* fmt, ...) {
  // GEOS notices (e.g. "Self-intersection at ...") are expected on bad input; we report through results.
  (void)fmt;
}

/// One GEOS context, destroyed with the object: calls from several threads each get their own.
class Context {
 public:
  Context() : h_(GEOS_init_r()) {
    GEOSContext_setNoticeHandler_r(h_, geos_message);
    GEOSContext_setErrorHandler_r(h_, geos_message);
  }
  ~Context() { GEOS_finish_r(h_); }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  GEOSContextHandle_t get() const { return h_; }

 private:
  GEOSContextHandle_t h_;
};

struct GeomDeleter {
  GEOSContextHandle_t h;
  void operator()(GEOSGeometry* g) const {
    if (g) GEOSGeom_destroy_r(h, g);
  }
};
using GeomPtr = std::unique_ptr<GEOSGeometry, GeomDeleter>;

inline GEOSGeometry* make_ring(GEOSContextHandle_t h, const Ring& ring) {
  if (ring.size() < 3) return nullptr;
  GEOSCoordSequence* seq = GEOSCoordSeq_create_r(h, static_cast<unsigned>(ring.size() + 1), 2);
  for (std::size_t i = 0; i <= ring.size(); ++i) {
    const Point2& p = ring[i % ring.size()];
    GEOSCoordSeq_setXY_r(h, seq, static_cast<unsigned>(i), p.x, p.y);
  }
  return GEOSGeom_createLinearRing_r(h, seq);
}

/// A polygon as GEOS geometry; nullptr if the outer ring has fewer than 3 points.
inline GEOSGeometry* make_polygon(GEOSContextHandle_t h, const Polygon& poly) {
  GEOSGeometry* shell = make_ring(h, poly.outer);
  if (!shell) return nullptr;
  std::vector<GEOSGeometry*> holes;
  for (const Ring& r : poly.holes)
    if (GEOSGeometry* g = make_ring(h, r)) holes.push_back(g);
  return GEOSGeom_createPolygon_r(h, shell, holes.data(), static_cast<unsigned>(holes.size()));
}

inline Ring ring_from(GEOSContextHandle_t h, const GEOSGeometry* ring) {
  const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(h, ring);
  unsigned n = 0;
  GEOSCoordSeq_getSize_r(h, seq, &n);
  Ring out;
  out.reserve(n);
  for (unsigned i = 0; i + 1 < n; ++i) {  // drop the closing vertex
    Point2 p;
    GEOSCoordSeq_getXY_r(h, seq, i, &p.x, &p.y);
    out.push_back(p);
  }
  return out;
}

inline Polygon polygon_from(GEOSContextHandle_t h, const GEOSGeometry* g) {
  Polygon p;
  p.outer = ring_from(h, GEOSGetExteriorRing_r(h, g));
  const int nh = GEOSGetNumInteriorRings_r(h, g);
  for (int i = 0; i < nh; ++i) p.holes.push_back(ring_from(h, GEOSGetInteriorRingN_r(h, g, i)));
  return p;
}

/// Polygonal parts of g (GeometryCollections from MakeValid may hold lines and points: dropped,
/// they have no area).
inline void collect_polygons(GEOSContextHandle_t h, const GEOSGeometry* g, std::vector<const GEOSGeometry*>& out) {
  const int type = GEOSGeomTypeId_r(h, g);
  if (type == GEOS_POLYGON) {
    if (!GEOSisEmpty_r(h, g)) out.push_back(g);
  } else if (type == GEOS_MULTIPOLYGON || type == GEOS_GEOMETRYCOLLECTION) {
    const int n = GEOSGetNumGeometries_r(h, g);
    for (int i = 0; i < n; ++i) collect_polygons(h, GEOSGetGeometryN_r(h, g, i), out);
  }
}

/// The union of all footprint polygons as one GEOS geometry (owned).
}  // namespace groundplan::gis::detail

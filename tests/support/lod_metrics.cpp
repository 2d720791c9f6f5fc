// SPDX-License-Identifier: MIT
#include "lod_metrics.h"

#include <geos_c.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace groundplan::testing {
namespace {

struct Geos {
  GEOSContextHandle_t h = GEOS_init_r();
  ~Geos() { GEOS_finish_r(h); }
};

GEOSGeometry* ring_geom(GEOSContextHandle_t h, const Ring& r) {
  GEOSCoordSequence* cs = GEOSCoordSeq_create_r(h, static_cast<unsigned>(r.size() + 1), 2);
  for (std::size_t i = 0; i <= r.size(); ++i) {
    const Point2& p = r[i % r.size()];
    GEOSCoordSeq_setXY_r(h, cs, static_cast<unsigned>(i), p.x, p.y);
  }
  return GEOSGeom_createLinearRing_r(h, cs);
}

GEOSGeometry* polygon_geom(GEOSContextHandle_t h, const Polygon& p) {
  std::vector<GEOSGeometry*> holes;
  for (const Ring& r : p.holes) holes.push_back(ring_geom(h, r));
  return GEOSGeom_createPolygon_r(h, ring_geom(h, p.outer), holes.data(), static_cast<unsigned>(holes.size()));
}

long double ring_area2(const Ring& r) {
  long double a = 0;
  for (std::size_t i = 1; i + 1 < r.size(); ++i)
    a += static_cast<long double>(r[i].x - r[0].x) * (r[i + 1].y - r[0].y) -
         static_cast<long double>(r[i + 1].x - r[0].x) * (r[i].y - r[0].y);
  return a;
}

struct Box {
  double minx, miny, maxx, maxy;
};

}  // namespace

LodMetrics measure_plans(const std::vector<GroundPlan>& plans, double small_hole_m2, double near_m, double gap_m) {
  Geos g;
  LodMetrics m;
  m.plans = plans.size();
  std::vector<GEOSGeometry*> geoms;
  std::vector<Box> boxes;
  for (const GroundPlan& p : plans) {
    m.holes += p.polygon.holes.size();
    m.vertices += p.polygon.outer.size();
    for (const Ring& h : p.polygon.holes) {
      m.vertices += h.size();
      if (small_hole_m2 > 0 && std::fabs(static_cast<double>(ring_area2(h))) / 2 < small_hole_m2) ++m.small_holes;
    }
    GEOSGeometry* geom = polygon_geom(g.h, p.polygon);
    double a = 0;
    GEOSArea_r(g.h, geom, &a);
    m.area_m2 += a;
    if (GEOSisValid_r(g.h, geom) != 1) ++m.invalid;
    geoms.push_back(geom);
    Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (const Point2& q : p.polygon.outer)
      b = {std::min(b.minx, q.x), std::min(b.miny, q.y), std::max(b.maxx, q.x), std::max(b.maxy, q.y)};
    boxes.push_back(b);
  }
  // Pairs whose boxes come within near_m: sweep over x.
  std::vector<std::size_t> order(plans.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return boxes[a].minx < boxes[b].minx; });
  const double reach = std::max(near_m, 0.0);
  for (std::size_t oi = 0; oi < order.size(); ++oi) {
    const std::size_t i = order[oi];
    for (std::size_t oj = oi + 1; oj < order.size() && boxes[order[oj]].minx <= boxes[i].maxx + reach; ++oj) {
      const std::size_t j = order[oj];
      if (boxes[j].miny > boxes[i].maxy + reach || boxes[i].miny > boxes[j].maxy + reach) continue;
      // Overlap: the interiors meet (relate pattern T********).
      if (GEOSRelatePattern_r(g.h, geoms[i], geoms[j], "T********") == 1) ++m.overlapping_pairs;
      if (near_m > 0) {
        double d = 0;
        if (GEOSDistance_r(g.h, geoms[i], geoms[j], &d) == 1 && d > 0 && d < near_m) ++m.close_pairs;
      }
    }
  }
  if (gap_m > 0 && !geoms.empty()) {
    GEOSGeometry* all =
        GEOSGeom_createCollection_r(g.h, GEOS_MULTIPOLYGON, geoms.data(), static_cast<unsigned>(geoms.size()));
    geoms.clear();  // owned by the collection now
    GEOSGeometry* u = GEOSUnaryUnion_r(g.h, all);
    GEOSBufferParams* bp = GEOSBufferParams_create_r(g.h);
    GEOSBufferParams_setJoinStyle_r(g.h, bp, GEOSBUF_JOIN_MITRE);
    GEOSBufferParams_setMitreLimit_r(g.h, bp, 10.0);
    GEOSGeometry* dil = GEOSBufferWithParams_r(g.h, u, bp, gap_m / 2);
    GEOSGeometry* clo = GEOSBufferWithParams_r(g.h, dil, bp, -gap_m / 2);
    GEOSGeometry* added = GEOSDifference_r(g.h, clo, u);
    double a = 0;
    if (!added || GEOSArea_r(g.h, added, &a) != 1) throw std::runtime_error("GEOS closing failed");
    m.closing_residual_m2 = a;
    if (std::getenv("GROUNDPLAN_LOD_DEBUG") && a > 0) {  // where is it? (for a person investigating)
      const int n = GEOSGetNumGeometries_r(g.h, added);
      for (int i = 0; i < n; ++i) {
        const GEOSGeometry* piece = GEOSGetGeometryN_r(g.h, added, i);
        double pa = 0;
        GEOSArea_r(g.h, piece, &pa);
        if (pa > 1e-4 * a || pa > 1e-6) {
          char* wkt = GEOSGeomToWKT_r(g.h, piece);
          std::fprintf(stderr, "closing residual piece %.3g m2: %.300s\n", pa, wkt);
          GEOSFree_r(g.h, wkt);
        }
      }
    }
    GEOSGeom_destroy_r(g.h, added);
    GEOSGeom_destroy_r(g.h, clo);
    GEOSGeom_destroy_r(g.h, dil);
    GEOSBufferParams_destroy_r(g.h, bp);
    GEOSGeom_destroy_r(g.h, u);
    GEOSGeom_destroy_r(g.h, all);
  }
  for (GEOSGeometry* geom : geoms) GEOSGeom_destroy_r(g.h, geom);
  return m;
}

}  // namespace groundplan::testing

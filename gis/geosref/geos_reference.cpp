// SPDX-License-Identifier: MIT
// GEOS UnaryUnion as the correctness reference, through the stable C API (geos_c.h).
#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <geos_c.h>
#include <gmpxx.h>

#include "below_pitch.h"
#include "geos_handles.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <memory>
#include <sstream>

namespace groundplan::gis {
namespace {

using namespace detail;  // geos_handles.h

GeomPtr union_of(GEOSContextHandle_t h, const std::vector<Footprint>& footprints) {
  std::vector<GEOSGeometry*> parts;
  for (const Footprint& f : footprints) {
    for (const Polygon& poly : f.polygons) {
      GEOSGeometry* g = make_polygon(h, poly);
      if (!g) continue;
      if (GEOSisValid_r(h, g) != 1) {
        GEOSGeometry* fixed = GEOSMakeValid_r(h, g);
        GEOSGeom_destroy_r(h, g);
        g = fixed;
        if (!g) continue;
      }
      parts.push_back(g);
    }
  }
  GeomPtr collection(GEOSGeom_createCollection_r(h, GEOS_GEOMETRYCOLLECTION, parts.data(),
                                                   static_cast<unsigned>(parts.size())),
                     GeomDeleter{h});
  GeomPtr u(GEOSUnaryUnion_r(h, collection.get()), GeomDeleter{h});
  if (!u) throw Error("GEOS UnaryUnion failed");
  return u;
}

GeomPtr geometry_of(GEOSContextHandle_t h, const std::vector<GroundPlan>& plans) {
  std::vector<GEOSGeometry*> parts;
  for (const GroundPlan& p : plans)
    if (GEOSGeometry* g = make_polygon(h, p.polygon)) parts.push_back(g);
  return GeomPtr(GEOSGeom_createCollection_r(h, GEOS_MULTIPOLYGON, parts.data(), static_cast<unsigned>(parts.size())),
                 GeomDeleter{h});
}

/// Even-odd membership of a rational point in one input polygon (all its rings), exactly.
bool covers_exactly(const Polygon& poly, const mpq_class& x, const mpq_class& y) {
  bool inside = false;
  auto ring_parity = [&](const Ring& r) {
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const Point2& a = r[i];
      const Point2& b = r[(i + 1) % n];
      const bool a_above = mpq_class(a.y) > y, b_above = mpq_class(b.y) > y;
      if (a_above == b_above) continue;
      // x < a.x + (y - a.y) (b.x - a.x) / (b.y - a.y)  <=>  sign-corrected cross product
      const mpq_class lhs = (x - a.x) * (mpq_class(b.y) - a.y);
      const mpq_class rhs = (y - a.y) * (mpq_class(b.x) - a.x);
      if ((b.y > a.y) ? lhs < rhs : lhs > rhs) inside = !inside;
    }
  };
  ring_parity(poly.outer);
  for (const Ring& h : poly.holes) ring_parity(h);
  return inside;
}

/// For a triangle ring (3 distinct vertices), whether its exact centroid lies inside some footprint.
/// Other rings: false (a general ring's centroid need not lie inside it).
bool triangle_centroid_covered(const Ring& ring, const std::vector<Footprint>& footprints) {
  Ring r;
  for (const Point2& p : ring)
    if (r.empty() || !(r.back() == p)) r.push_back(p);
  if (r.size() > 1 && r.front() == r.back()) r.pop_back();
  if (r.size() != 3) return false;
  const mpq_class cx = (mpq_class(r[0].x) + r[1].x + r[2].x) / 3;
  const mpq_class cy = (mpq_class(r[0].y) + r[1].y + r[2].y) / 3;
  const double dx = cx.get_d(), dy = cy.get_d();
  for (const Footprint& f : footprints)
    for (const Polygon& poly : f.polygons) {
      double minx = INFINITY, miny = INFINITY, maxx = -INFINITY, maxy = -INFINITY;
      for (const Point2& p : poly.outer) {
        minx = std::min(minx, p.x), maxx = std::max(maxx, p.x), miny = std::min(miny, p.y), maxy = std::max(maxy, p.y);
      }
      if (dx < minx - 1 || dx > maxx + 1 || dy < miny - 1 || dy > maxy + 1) continue;
      if (covers_exactly(poly, cx, cy)) return true;
    }
  return false;
}

}  // namespace

std::vector<GroundPlan> geos_union(const std::vector<Footprint>& footprints) {
  Context ctx;
  const GEOSContextHandle_t h = ctx.get();
  GeomPtr u = union_of(h, footprints);
  std::vector<const GEOSGeometry*> polys;
  collect_polygons(h, u.get(), polys);
  std::vector<GroundPlan> plans;
  plans.reserve(polys.size());
  for (const GEOSGeometry* g : polys) {
    GroundPlan plan;
    plan.polygon = polygon_from(h, g);
    GEOSArea_r(h, g, &plan.area_m2);
    plans.push_back(std::move(plan));
  }
  return plans;
}

bool GeosComparison::matches(double rel_tol) const {
  const double scale = std::max(area_geos, area_ours);
  return (symdiff_area <= rel_tol * scale || below_pitch()) && (counts_exact() || below_pitch()) &&
         holes_ours_covered == 0 && invalid_ours == 0 && overlapping_ours == 0;
}

std::string GeosComparison::summary() const {
  std::ostringstream s;
  s.precision(12);
  s << "area ours " << area_ours << " m2, GEOS " << area_geos << " m2, symmetric difference " << symdiff_area
    << " m2 (" << (area_geos > 0 ? symdiff_area / area_geos : 0.0) << " relative); polygons " << polygons_ours << " vs "
    << polygons_geos << "; holes " << holes_ours << " vs " << holes_geos << "; invalid " << invalid_ours
    << "; overlapping pairs " << overlapping_ours;
  if (holes_geos_artifacts)
    s << "; " << holes_geos_artifacts << " GEOS holes are not holes of the input (exactly covered: not counted)";
  if (holes_ours_covered) s << "; " << holes_ours_covered << " of our holes are covered by an input footprint";
  if (differences_checked)
    s << (differences_below_pitch ? "; every difference is narrower than the snap pitch ("
                                  : "; a difference is not below the snap pitch (")
      << pitch_m << " m)" << (first_difference_not_below_pitch.empty() ? "" : ": " + first_difference_not_below_pitch);
  if (!first_invalid_reason.empty()) s << "; first invalid: " << first_invalid_reason;
  return s.str();
}

double snap_pitch_of(const std::vector<Footprint>& footprints) {
  double m = 0;
  auto ring = [&](const Ring& r) {
    for (const Point2& q : r)
      if (std::isfinite(q.x) && std::isfinite(q.y)) m = std::max({m, std::fabs(q.x), std::fabs(q.y)});
  };
  for (const Footprint& f : footprints)
    for (const Polygon& p : f.polygons) {
      ring(p.outer);
      for (const Ring& h : p.holes) ring(h);
    }
  return snap_pitch(m);
}

GeosComparison compare_with_geos(const std::vector<Footprint>& footprints, const std::vector<GroundPlan>& plans,
                                 const std::vector<GroundPlan>* reference) {
  Context ctx;
  const GEOSContextHandle_t h = ctx.get();
  GeosComparison c;

  GeomPtr ref;
  if (reference) {
    ref = geometry_of(h, *reference);
  } else {
    ref = union_of(h, footprints);
  }
  std::vector<const GEOSGeometry*> ref_polys;
  collect_polygons(h, ref.get(), ref_polys);
  c.polygons_geos = ref_polys.size();
  for (const GEOSGeometry* g : ref_polys) {
    const int nh = GEOSGetNumInteriorRings_r(h, g);
    c.holes_geos += static_cast<std::size_t>(nh);
    for (int i = 0; i < nh; ++i)
      c.holes_geos_artifacts += triangle_centroid_covered(ring_from(h, GEOSGetInteriorRingN_r(h, g, i)), footprints);
  }
  GEOSArea_r(h, ref.get(), &c.area_geos);

  // Our plans one by one: validity, holes; then as a whole for the area comparison.
  std::vector<GEOSGeometry*> ours;
  for (const GroundPlan& p : plans) {
    GEOSGeometry* g = make_polygon(h, p.polygon);
    if (!g) {
      ++c.invalid_ours;
      if (c.first_invalid_reason.empty()) c.first_invalid_reason = "outer ring with fewer than 3 points";
      continue;
    }
    if (GEOSisValid_r(h, g) != 1) {
      ++c.invalid_ours;
      if (c.first_invalid_reason.empty()) {
        char* reason = GEOSisValidReason_r(h, g);
        c.first_invalid_reason = reason ? reason : "invalid";
        GEOSFree_r(h, reason);
      }
    }
    ++c.polygons_ours;
    c.holes_ours += p.polygon.holes.size();
    for (const Ring& hole : p.polygon.holes) c.holes_ours_covered += triangle_centroid_covered(hole, footprints);
    ours.push_back(g);
  }
  // Overlaps between plans: interiors must be disjoint (touching is allowed). STRtree for pairs.
  {
    GEOSSTRtree* tree = GEOSSTRtree_create_r(h, 10);
    for (std::size_t i = 0; i < ours.size(); ++i) GEOSSTRtree_insert_r(h, tree, ours[i], reinterpret_cast<void*>(i));
    struct QueryState {
      GEOSContextHandle_t h;
      const std::vector<GEOSGeometry*>* geoms;
      std::size_t self;
      std::size_t overlaps = 0;
    };
    for (std::size_t i = 0; i < ours.size(); ++i) {
      QueryState st{h, &ours, i};
      GEOSSTRtree_query_r(
          h, tree, ours[i],
          [](void* item, void* user) {
            auto* s = static_cast<QueryState*>(user);
            const auto j = reinterpret_cast<std::size_t>(item);
            if (j <= s->self) return;
            // Interiors intersect <=> DE-9IM pattern T******** .
            if (GEOSRelatePattern_r(s->h, (*s->geoms)[s->self], (*s->geoms)[j], "T********") == 1) ++s->overlaps;
          },
          &st);
      c.overlapping_ours += st.overlaps;
    }
    GEOSSTRtree_destroy_r(h, tree);
  }
  for (GEOSGeometry* g : ours) {
    double a = 0;
    GEOSArea_r(h, g, &a);
    c.area_ours += a;
  }
  GeomPtr ours_all(GEOSGeom_createCollection_r(h, GEOS_MULTIPOLYGON, ours.data(), static_cast<unsigned>(ours.size())),
                   GeomDeleter{h});
  // Symmetric difference of possibly invalid geometry can throw in GEOS: repair ours first when needed.
  GeomPtr ours_valid(c.invalid_ours || c.overlapping_ours ? GEOSUnaryUnion_r(h, ours_all.get()) : nullptr,
                     GeomDeleter{h});
  const GEOSGeometry* a = ours_valid ? ours_valid.get() : ours_all.get();
  GeomPtr sd(GEOSSymDifference_r(h, a, ref.get()), GeomDeleter{h});
  if (!sd) {
    c.symdiff_area = std::numeric_limits<double>::infinity();
  } else {
    GEOSArea_r(h, sd.get(), &c.symdiff_area);
  }
  // Issue 20: the engine collapses features narrower than its snap pitch, which GEOS's exact union keeps.
  // Where counts or areas differ, whether only by such features (below_pitch.h).
  const double scale = std::max(c.area_geos, c.area_ours);
  const bool area_off = !(c.symdiff_area <= 1e-10 * scale);
  if (!c.counts_exact() || area_off) {
    c.pitch_m = snap_pitch_of(footprints);
    std::vector<Polygon> ours_p, geos_p;
    for (const GroundPlan& p : plans) ours_p.push_back(p.polygon);
    for (const GEOSGeometry* g : ref_polys) geos_p.push_back(polygon_from(h, g));
    const BelowPitch b = differences_below_pitch(ours_p, geos_p, c.pitch_m);
    c.differences_checked = true;
    c.differences_below_pitch = b.all;
    c.first_difference_not_below_pitch = b.first_not;
  }
  return c;
}

std::string to_wkt(const Polygon& polygon) {
  Context ctx;
  const GEOSContextHandle_t h = ctx.get();
  GeomPtr g(make_polygon(h, polygon), GeomDeleter{h});
  if (!g) return "POLYGON EMPTY";
  GEOSWKTWriter* w = GEOSWKTWriter_create_r(h);
  GEOSWKTWriter_setTrim_r(h, w, 1);
  GEOSWKTWriter_setRoundingPrecision_r(h, w, 17);
  char* s = GEOSWKTWriter_write_r(h, w, g.get());
  std::string out = s ? s : "";
  GEOSFree_r(h, s);
  GEOSWKTWriter_destroy_r(h, w);
  return out;
}

std::vector<Polygon> polygons_from_wkt(const std::string& wkt) {
  Context ctx;
  const GEOSContextHandle_t h = ctx.get();
  GEOSWKTReader* r = GEOSWKTReader_create_r(h);
  GeomPtr g(GEOSWKTReader_read_r(h, r, wkt.c_str()), GeomDeleter{h});
  GEOSWKTReader_destroy_r(h, r);
  if (!g) throw InvalidArgument("cannot parse WKT: " + wkt.substr(0, 80));
  std::vector<const GEOSGeometry*> polys;
  collect_polygons(h, g.get(), polys);
  std::vector<Polygon> out;
  for (const GEOSGeometry* p : polys) out.push_back(polygon_from(h, p));
  return out;
}

}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
// GEOS UnaryUnion as the correctness reference, through the stable C API (geos_c.h).
#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <geos_c.h>

#include "adjudicate.h"
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

/// WKT of g, cut after `limit` characters.
std::string truncated_wkt(GEOSContextHandle_t h, const GEOSGeometry* g, std::size_t limit) {
  GEOSWKTWriter* w = GEOSWKTWriter_create_r(h);
  GEOSWKTWriter_setTrim_r(h, w, 1);
  GEOSWKTWriter_setRoundingPrecision_r(h, w, 15);
  char* text = GEOSWKTWriter_write_r(h, w, g);
  std::string out = text ? text : "";
  GEOSFree_r(h, text);
  GEOSWKTWriter_destroy_r(h, w);
  if (out.size() > limit) out = out.substr(0, limit) + "...";
  return out;
}

/// Names of the buildings at a point: the footprints covering it, else the members of our plans covering it.
std::string buildings_at(const Point2& p, const std::vector<Footprint>& footprints, const std::vector<GroundPlan>& plans,
                         const PolygonIndex& input, const PolygonIndex& ours) {
  std::vector<std::size_t> fps = input.covering(p);
  if (fps.empty())
    for (std::size_t plan : ours.covering(p)) fps.insert(fps.end(), plans[plan].members.begin(), plans[plan].members.end());
  std::sort(fps.begin(), fps.end());
  fps.erase(std::unique(fps.begin(), fps.end()), fps.end());
  std::string out;
  std::size_t named = 0;
  for (std::size_t i : fps) {
    if (i >= footprints.size()) continue;
    if (named == 8) {
      out += ", ...";
      break;
    }
    out += (named++ ? ", " : "") + (footprints[i].source_id.empty() ? "#" + std::to_string(i) : footprints[i].source_id);
  }
  return out.empty() ? "none" : out;
}

/// Every piece of ours XOR GEOS (`sd`) decided exactly against the input (adjudicate.h).
void adjudicate(GEOSContextHandle_t h, const GEOSGeometry* sd, const std::vector<Footprint>& footprints,
                const std::vector<GroundPlan>& plans, const PolygonIndex& input, const PolygonIndex& ours,
                const PolygonIndex& geos, GeosComparison& c) {
  c.adjudicated = true;
  std::vector<const GEOSGeometry*> pieces;
  collect_polygons(h, sd, pieces);
  const double pitch = pieces.empty() ? 0 : snap_pitch_of(footprints);
  for (const GEOSGeometry* piece : pieces) {
    const PieceDecision d = decide_piece(h, piece, input, ours, geos, 1.5 * pitch);
    double area = 0;
    GEOSArea_r(h, piece, &area);
    if (d.decision == Decision::Noise) continue;
    if (d.decision == Decision::OursBelowPitch) {
      ++c.places_ours_below_pitch;
      continue;
    }
    if (d.decision == Decision::GeosWrong) {
      ++c.places_geos_wrong;
      c.largest_geos_wrong_m2 = std::max(c.largest_geos_wrong_m2, area);
      continue;
    }
    if (d.decision == Decision::Undecided && piece_narrower_than(h, piece, 1.5 * pitch)) {
      ++c.places_ours_below_pitch;
      continue;
    }
    ++(d.decision == Decision::OursWrong ? c.places_ours_wrong : c.places_undecided);
    c.largest_ours_wrong_m2 = std::max(c.largest_ours_wrong_m2, area);
    if (!c.first_ours_wrong.empty()) continue;
    std::ostringstream s;
    s.precision(17);
    if (d.decision == Decision::OursWrong)
      s << "at (" << d.witness.x << " " << d.witness.y << ") the input "
        << (d.input_covers ? "covers and our plans do not" : "does not cover and our plans do");
    else
      s << "undecided (every point tried lies on an edge)";
    s.precision(6);
    s << ": a region of " << area << " m2, " << truncated_wkt(h, piece, 300) << "; buildings "
      << buildings_at(d.witness, footprints, plans, input, ours);
    c.first_ours_wrong = s.str();
  }
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
  if (holes_ours_covered != 0 || invalid_ours != 0 || overlapping_ours != 0 || edge_touching_ours != 0) return false;
  // Adjudicated, every place where the counts can differ has been decided: a plan GEOS drops, splits or joins
  // and a hole it invents or closes are pieces of the difference; what has no area (two plans that should be
  // one, sharing an edge) is edge_touching_ours.
  if (adjudicated) return places_ours_wrong == 0 && places_undecided == 0;
  if (!(counts_exact() || below_pitch())) return false;
  const double scale = std::max(area_geos, area_ours);
  return symdiff_area <= rel_tol * scale || below_pitch();
}

GeosComparison::Verdict GeosComparison::verdict(double rel_tol) const {
  if (!matches(rel_tol)) return Verdict::Mismatch;
  return places_geos_wrong > 0 || holes_geos_artifacts > 0 || holes_geos_dropped > 0 ? Verdict::MatchGeosDiffers
                                                                                     : Verdict::Match;
}

std::string GeosComparison::verdict_line() const {
  std::ostringstream s;
  s.precision(3);
  switch (verdict()) {
    case Verdict::Match:
      s << "MATCH";
      break;
    case Verdict::MatchGeosDiffers:
      s << "MATCH: GEOS differs in " << places_geos_wrong << (places_geos_wrong == 1 ? " place" : " places")
        << ", each decided in our favour: largest " << largest_geos_wrong_m2 << " m2";
      break;
    case Verdict::Mismatch:
      s << "MISMATCH";
      if (places_ours_wrong + places_undecided > 0)
        s << ": our plans differ from the input footprints in " << places_ours_wrong
          << (places_ours_wrong == 1 ? " place" : " places") << " (largest " << largest_ours_wrong_m2 << " m2)"
          << (places_undecided ? ", " + std::to_string(places_undecided) + " undecided" : std::string()) << "; "
          << first_ours_wrong;
      break;
  }
  return s.str();
}

std::string GeosComparison::summary() const {
  std::ostringstream s;
  s.precision(12);
  s << "area ours " << area_ours << " m2, GEOS " << area_geos << " m2, symmetric difference " << symdiff_area
    << " m2 (" << (area_geos > 0 ? symdiff_area / area_geos : 0.0) << " relative); polygons " << polygons_ours << " vs "
    << polygons_geos << "; holes " << holes_ours << " vs " << holes_geos << "; invalid " << invalid_ours
    << "; overlapping pairs " << overlapping_ours;
  if (edge_touching_ours) s << "; pairs sharing an edge " << edge_touching_ours;
  if (holes_geos_artifacts)
    s << "; " << holes_geos_artifacts << " GEOS holes are not holes of the input (exactly covered: not counted)";
  if (holes_geos_dropped) s << "; " << holes_geos_dropped << " of our holes are real holes of the input that GEOS closed";
  if (holes_ours_covered) s << "; " << holes_ours_covered << " of our holes are covered by an input footprint";
  if (adjudicated)
    s << "; differences decided exactly against the input: GEOS wrong in " << places_geos_wrong << ", ours wrong in "
      << places_ours_wrong << " (" << places_ours_below_pitch << " more narrower than the snap pitch), undecided "
      << places_undecided;
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
  std::vector<Polygon> geos_p;
  for (const GEOSGeometry* g : ref_polys) geos_p.push_back(polygon_from(h, g));
  // Exact point location (adjudicate.h) in the input footprints (the truth), GEOS's polygons and our plans.
  std::vector<const Polygon*> input_polys, geos_polys, our_polys;
  std::vector<std::size_t> input_owner, geos_owner, our_owner;
  for (std::size_t i = 0; i < footprints.size(); ++i)
    for (const Polygon& p : footprints[i].polygons) input_polys.push_back(&p), input_owner.push_back(i);
  for (std::size_t i = 0; i < geos_p.size(); ++i) geos_polys.push_back(&geos_p[i]), geos_owner.push_back(i);
  for (std::size_t i = 0; i < plans.size(); ++i) our_polys.push_back(&plans[i].polygon), our_owner.push_back(i);
  const PolygonIndex input(h, std::move(input_polys), std::move(input_owner));
  const PolygonIndex geos_index(h, std::move(geos_polys), std::move(geos_owner));
  const PolygonIndex our_index(h, std::move(our_polys), std::move(our_owner));
  c.polygons_geos = ref_polys.size();
  for (const Polygon& g : geos_p) {
    c.holes_geos += g.holes.size();
    for (const Ring& hole : g.holes) c.holes_geos_artifacts += ring_inside(h, hole, input, geos_index) == Side::In;
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
    for (const Ring& hole : p.polygon.holes) {
      Point2 at;
      const Side truth = ring_inside(h, hole, input, our_index, &at);
      // Covered: wrong, unless only within 1.5 snap pitches of the input's edges (snap rounding's doing).
      c.holes_ours_covered += truth == Side::In && !input.near_edge(at, 1.5 * snap_pitch_of(footprints));
      c.holes_geos_dropped += truth == Side::Out && ring_inside(h, hole, geos_index, our_index) == Side::In;
    }
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
      std::size_t touching = 0;
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
            // Boundaries sharing a segment (interiors apart): one plan written as two.
            else if (GEOSRelatePattern_r(s->h, (*s->geoms)[s->self], (*s->geoms)[j], "F***1****") == 1) ++s->touching;
          },
          &st);
      c.overlapping_ours += st.overlaps;
      c.edge_touching_ours += st.touching;
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
  if (!reference && sd) adjudicate(h, sd.get(), footprints, plans, input, our_index, geos_index, c);
  // Issue 20: the engine collapses features narrower than its snap pitch, which GEOS's exact union keeps.
  // Where counts or areas differ, whether only by such features (below_pitch.h).
  const double scale = std::max(c.area_geos, c.area_ours);
  const bool area_off = !(c.symdiff_area <= 1e-10 * scale);
  if (!c.counts_exact() || area_off) {
    c.pitch_m = snap_pitch_of(footprints);
    std::vector<Polygon> ours_p;
    for (const GroundPlan& p : plans) ours_p.push_back(p.polygon);
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

// SPDX-License-Identifier: MIT
#pragma once
// The correctness reference (DESIGN.md "Correctness is checked against GEOS"): GEOS UnaryUnion of the
// same footprints through the stable C API, and a comparison of our plans with it. Used by
// `groundplan --verify`, by the tests and by the benchmarks. Thread-safe (one GEOS context per call).
#include <groundplan/types.h>
#include <string>
#include <vector>

namespace groundplan::gis {

/// GEOS UnaryUnion of every polygon of every footprint, split into one GroundPlan per polygon
/// (members left empty). Input polygons are made valid with GEOSMakeValid first when GEOS finds them
/// invalid (self-intersections, repeated points, zero area), as our engine must cope with them too.
std::vector<GroundPlan> geos_union(const std::vector<Footprint>& footprints);

struct GeosComparison {
  double area_ours = 0;            // m²
  double area_geos = 0;
  double symdiff_area = 0;         // area of (ours XOR geos)
  std::size_t polygons_ours = 0, polygons_geos = 0;
  std::size_t holes_ours = 0, holes_geos = 0;
  /// GEOS holes proven not to be holes of the input: a point strictly inside them lies, exactly, inside an
  /// input footprint. GEOS computes in floating point with snapping and, on real data,
  /// leaves such 1e-11 m² triangles where neighbours' walls meet one ulp apart.
  std::size_t holes_geos_artifacts = 0;
  /// Our holes proven wrong the same way (a point strictly inside them is covered by an input footprint).
  std::size_t holes_ours_covered = 0;
  /// Where the counts differ or the symmetric difference is over 1e-10 of the area: whether the plans differ
  /// from GEOS's union only by material narrower than 1.5 snap pitches (`pitch_m` = groundplan::snap_pitch of
  /// the largest coordinate; gis/geosref/below_pitch.h). Issue 20: vertices closer than the pitch are one
  /// vertex, so gaps and necks narrower than it close and holes narrower than it collapse, which GEOS's exact
  /// union keeps, and walls move by up to a pitch along their length.
  bool differences_checked = false;
  bool differences_below_pitch = false;
  double pitch_m = 0;
  std::string first_difference_not_below_pitch;
  /// Where our plans and GEOS's union differ, each piece of the difference decided exactly against the input
  /// footprints (gis/geosref/adjudicate.h; only when GEOS's union is computed here, `reference` null): GEOS's
  /// floating-point overlay keeps sub-µm² holes the input covers and closes holes that are real.
  bool adjudicated = false;
  std::size_t places_geos_wrong = 0;      // pieces where ours agrees with the input and GEOS does not
  double largest_geos_wrong_m2 = 0;
  std::size_t places_ours_wrong = 0;      // pieces where ours disagrees with the input, wider than 1.5 snap pitches
  std::size_t places_ours_below_pitch = 0;// pieces where ours disagrees with the input, narrower (snap rounding)
  std::size_t places_undecided = 0;       // pieces wider than the pitch with no point off every edge
  double largest_ours_wrong_m2 = 0;
  /// The first piece where ours is wrong (or undecided), for a person: where, how large, which buildings.
  std::string first_ours_wrong;
  /// GEOS holes that are real holes of the input which GEOS's union closed (our holes, decided exactly).
  std::size_t holes_geos_dropped = 0;
  std::size_t invalid_ours = 0;    // plans that GEOSisValid rejects
  std::size_t overlapping_ours = 0;// pairs of our plans whose interiors overlap
  std::size_t edge_touching_ours = 0;  // pairs of our plans whose boundaries share a segment (should be one plan)
  std::string first_invalid_reason;
  /// The DESIGN.md criterion: all valid, no overlaps, no two plans sharing an edge, none of our holes covered
  /// by the input; when adjudicated, no piece of the difference where ours is wrong beyond the snap pitch (or
  /// undecided); else the same counts (GEOS's proven artifacts and dropped holes accounted for) and
  /// symdiff <= rel_tol * area.
  /// Counts and areas that differ only by features narrower than the snap pitch match too (below_pitch).
  bool matches(double rel_tol = 1e-9) const;
  bool counts_exact() const {
    return polygons_ours == polygons_geos && holes_ours == holes_geos - holes_geos_artifacts + holes_geos_dropped;
  }
  /// MATCH, MATCH where GEOS differs and each place is decided in our favour, or MISMATCH.
  enum class Verdict { Match, MatchGeosDiffers, Mismatch };
  Verdict verdict(double rel_tol = 1e-9) const;
  /// "MATCH", "MATCH: GEOS differs in N places, each decided in our favour: largest X m2" or "MISMATCH: ...".
  std::string verdict_line() const;
  bool below_pitch() const { return differences_checked && differences_below_pitch; }
  std::string summary() const;     // one line for a person
};

/// The union's snap pitch for `footprints` (groundplan::snap_pitch of their largest finite coordinate
/// magnitude): the one compare_with_geos measures differences below.
double snap_pitch_of(const std::vector<Footprint>& footprints);

/// Compares `plans` with GEOS UnaryUnion of `footprints` (computed here unless `reference` is given).
GeosComparison compare_with_geos(const std::vector<Footprint>& footprints, const std::vector<GroundPlan>& plans,
                                 const std::vector<GroundPlan>* reference = nullptr);

/// WKT of a polygon (for messages and golden files) and the reverse, through GEOS.
std::string to_wkt(const Polygon& polygon);
std::vector<Polygon> polygons_from_wkt(const std::string& wkt);  // Polygon or MultiPolygon; throws InvalidArgument

}  // namespace groundplan::gis

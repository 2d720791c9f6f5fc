// SPDX-License-Identifier: MIT
#pragma once
// Who is right where our plans and GEOS's union differ (used by compare_with_geos, so by `groundplan
// --verify`, `--stats` and the Python module's verify). GEOS's overlay works in floating point and, on real
// data, keeps a sub-µm² "hole" that input polygons cover exactly or closes one that is real; a check that
// takes GEOS's word cries wolf. Here every piece of the symmetric difference is decided exactly: points
// strictly inside the piece (double points, checked inside one of its triangles with the engine's exact
// orientation predicate) are classified against the input footprints (the truth: the union of their
// even-odd regions, as the engine defines it), against our plans and against GEOS's polygons, each with
// robust::orient, so a point on an edge is known to be on it and is not used.
#include <groundplan/types.h>

#include <geos_c.h>

#include <memory>
#include <string>
#include <vector>

namespace groundplan::gis::detail {

/// Where a point lies against a set of polygons, exactly.
enum class Side { In, On, Out };  // strictly inside one (even-odd over its rings); on an edge of one, inside none; outside all

/// Polygons behind an STR tree of their boxes, for exact point location.
class PolygonIndex {
 public:
  /// `owner[i]` is what polygon i belongs to (a footprint's or a plan's index), returned by covering().
  PolygonIndex(GEOSContextHandle_t h, std::vector<const Polygon*> polys, std::vector<std::size_t> owner);
  ~PolygonIndex();
  PolygonIndex(const PolygonIndex&) = delete;
  PolygonIndex& operator=(const PolygonIndex&) = delete;
  Side side(const Point2& p) const;
  /// Whether p lies within w of an edge of some polygon (double arithmetic: a tolerance, not a sign).
  bool near_edge(const Point2& p, double w) const;
  /// Owners of the polygons that contain p strictly, ascending, each once.
  std::vector<std::size_t> covering(const Point2& p) const;

 private:
  std::vector<std::size_t> candidates(const Point2& p, double w = 0) const;
  GEOSContextHandle_t h_;
  std::vector<const Polygon*> polys_;
  std::vector<std::size_t> owner_;
  std::vector<GEOSGeometry*> boxes_;
  GEOSSTRtree* tree_ = nullptr;
};

/// The exact side of p against one polygon's rings (even-odd).
Side side_of(const Polygon& poly, const Point2& p);

/// Points strictly inside `g` (a GEOS polygon), exactly: up to `max_points`, from its largest triangles
/// (GEOS's constrained Delaunay triangulation) first, each checked strictly inside g with side_of.
std::vector<Point2> interior_points(GEOSContextHandle_t h, const GEOSGeometry* g, std::size_t max_points = 24);

enum class Decision {
  Noise,      // every usable point is on the same side of ours and GEOS's: a float sliver of the difference itself
  GeosWrong,  // ours agrees with the input there, GEOS does not
  OursWrong,  // ours disagrees with the input there, farther than w from the input's edges
  OursBelowPitch,  // ours disagrees with the input only within w of its edges (snap rounding moves edges that far)
  Undecided,  // no usable point (all on an edge)
};

struct PieceDecision {
  Decision decision = Decision::Undecided;
  Point2 witness;                 // a point of the piece where the decision was taken
  bool input_covers = false;      // at the witness (OursWrong: whether the input covers it, ours not)
};

/// One piece of ours XOR GEOS, decided point by point against the truth (input), ours and GEOS. Where ours
/// disagrees with the input within w of the input's edges (w: 1.5 snap pitches), it is snap rounding's doing:
/// OursBelowPitch unless ours is wrong farther out somewhere (OursWrong) or GEOS is wrong too (GeosWrong).
PieceDecision decide_piece(GEOSContextHandle_t h, const GEOSGeometry* piece, const PolygonIndex& input,
                           const PolygonIndex& ours, const PolygonIndex& geos, double w);

/// Whether `index` covers the inside of ring `r`, a hole of one of the polygons of `own` (ours or GEOS's): Side
/// of the first usable point inside the ring and outside every polygon of `own` (islands in the hole are
/// other polygons), put in `where`; On when none is usable.
Side ring_inside(GEOSContextHandle_t h, const Ring& r, const PolygonIndex& index, const PolygonIndex& own,
                 Point2* where = nullptr);

/// Whether a piece (of a symmetric difference, any coordinates) is narrower than w (below_pitch.h), measured
/// about a local origin so that widths of 1e-8 m at coordinates of 1e6 m are resolved.
bool piece_narrower_than(GEOSContextHandle_t h, const GEOSGeometry* piece, double w);

}  // namespace groundplan::gis::detail

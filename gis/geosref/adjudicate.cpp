// SPDX-License-Identifier: MIT
// Exact decisions where our plans and GEOS's union differ (see adjudicate.h).
#include "adjudicate.h"

#include "below_pitch.h"
#include "geos_handles.h"
#include "robust/predicates.h"

#include <algorithm>
#include <cmath>

namespace groundplan::gis::detail {
namespace {

/// The exact side of p against ring r for the even-odd rule: false when p lies on an edge, else `in`
/// toggled once per edge crossing the horizontal ray from p to +x.
bool ring_parity(const Ring& r, const Point2& p, bool& in) {
  const std::size_t n = r.size();
  if (n < 3) return true;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2& a = r[i];
    const Point2& b = r[i + 1 < n ? i + 1 : 0];
    if (a == b) continue;
    const bool crosses = (a.y > p.y) != (b.y > p.y);
    const bool in_box = std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
                        p.y <= std::max(a.y, b.y);
    if (!crosses && !in_box) continue;
    const int o = robust::orient(a, b, p);
    if (o == 0 && in_box) return false;
    // The edge seen going up: the crossing lies right of p when p lies left of it.
    if (crosses && (b.y > a.y ? o : -o) > 0) in = !in;
  }
  return true;
}

}  // namespace

Side side_of(const Polygon& poly, const Point2& p) {
  bool in = false;
  if (!ring_parity(poly.outer, p, in)) return Side::On;
  for (const Ring& h : poly.holes)
    if (!ring_parity(h, p, in)) return Side::On;
  return in ? Side::In : Side::Out;
}

PolygonIndex::PolygonIndex(GEOSContextHandle_t h, std::vector<const Polygon*> polys, std::vector<std::size_t> owner)
    : h_(h), polys_(std::move(polys)), owner_(std::move(owner)) {
  tree_ = GEOSSTRtree_create_r(h_, 10);
  boxes_.reserve(polys_.size());
  for (std::size_t i = 0; i < polys_.size(); ++i) {
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (const Point2& q : polys_[i]->outer) {
      x0 = std::min(x0, q.x), y0 = std::min(y0, q.y), x1 = std::max(x1, q.x), y1 = std::max(y1, q.y);
    }
    if (!(x0 <= x1 && y0 <= y1)) continue;  // empty or not finite: covers nothing
    GEOSGeometry* box = GEOSGeom_createRectangle_r(h_, x0, y0, x1, y1);
    if (!box) continue;
    boxes_.push_back(box);
    GEOSSTRtree_insert_r(h_, tree_, box, reinterpret_cast<void*>(i));
  }
}

PolygonIndex::~PolygonIndex() {
  GEOSSTRtree_destroy_r(h_, tree_);
  for (GEOSGeometry* g : boxes_) GEOSGeom_destroy_r(h_, g);
}

std::vector<std::size_t> PolygonIndex::candidates(const Point2& p, double w) const {
  std::vector<std::size_t> out;
  GeomPtr q(w > 0 ? GEOSGeom_createRectangle_r(h_, p.x - w, p.y - w, p.x + w, p.y + w)
                  : GEOSGeom_createPointFromXY_r(h_, p.x, p.y),
            GeomDeleter{h_});
  GEOSSTRtree_query_r(
      h_, tree_, q.get(),
      [](void* item, void* user) { static_cast<std::vector<std::size_t>*>(user)->push_back(reinterpret_cast<std::size_t>(item)); },
      &out);
  std::sort(out.begin(), out.end());
  return out;
}

bool PolygonIndex::near_edge(const Point2& p, double w) const {
  auto ring_near = [&](const Ring& r) {
    for (std::size_t i = 0, n = r.size(); i < n; ++i) {
      const Point2& a = r[i];
      const Point2& b = r[i + 1 < n ? i + 1 : 0];
      const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
      double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0;
      t = std::clamp(t, 0.0, 1.0);
      if (std::hypot(a.x + t * dx - p.x, a.y + t * dy - p.y) <= w) return true;
    }
    return false;
  };
  for (std::size_t i : candidates(p, w)) {
    if (ring_near(polys_[i]->outer)) return true;
    for (const Ring& r : polys_[i]->holes)
      if (ring_near(r)) return true;
  }
  return false;
}

Side PolygonIndex::side(const Point2& p) const {
  bool on = false;
  for (std::size_t i : candidates(p)) {
    const Side s = side_of(*polys_[i], p);
    if (s == Side::In) return Side::In;
    on |= s == Side::On;
  }
  return on ? Side::On : Side::Out;
}

std::vector<std::size_t> PolygonIndex::covering(const Point2& p) const {
  std::vector<std::size_t> out;
  for (std::size_t i : candidates(p))
    if (side_of(*polys_[i], p) == Side::In) out.push_back(owner_[i]);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

struct Tri {
  Point2 a, b, c;
  double area;
};

/// The triangles of GEOS's constrained Delaunay triangulation of g, largest first.
std::vector<Tri> triangles_of(GEOSContextHandle_t h, const GEOSGeometry* g) {
  std::vector<Tri> all;
  GeomPtr tris(GEOSConstrainedDelaunayTriangulation_r(h, g), GeomDeleter{h});
  if (!tris) return all;
  const int n = GEOSGetNumGeometries_r(h, tris.get());
  for (int i = 0; i < n; ++i) {
    const Ring r = ring_from(h, GEOSGetExteriorRing_r(h, GEOSGetGeometryN_r(h, tris.get(), i)));
    if (r.size() != 3) continue;
    const double area = std::fabs((r[1].x - r[0].x) * (r[2].y - r[0].y) - (r[1].y - r[0].y) * (r[2].x - r[0].x)) / 2;
    all.push_back({r[0], r[1], r[2], area});
  }
  std::sort(all.begin(), all.end(), [](const Tri& x, const Tri& y) { return x.area > y.area; });
  return all;
}

}  // namespace

std::vector<Point2> interior_points(GEOSContextHandle_t h, const GEOSGeometry* g, std::size_t max_points) {
  std::vector<Point2> out;
  const Polygon poly = polygon_from(h, g);
  // GEOS triangulates what it takes for a polygon; where that fails (a hole touching the shell) or gives
  // nothing, the shell alone. Either way every point is kept only when exactly inside the polygon.
  std::vector<Tri> all = triangles_of(h, g);
  if (all.empty()) {
    GeomPtr shell(make_polygon(h, Polygon{poly.outer, {}}), GeomDeleter{h});
    if (shell) all = triangles_of(h, shell.get());
  }
  // The centroids first (largest triangles first), then the points nearer each corner, rounded to doubles.
  static constexpr double kWeights[4][3] = {{1 / 3.0, 1 / 3.0, 1 / 3.0}, {0.5, 0.25, 0.25}, {0.25, 0.5, 0.25}, {0.25, 0.25, 0.5}};
  for (const auto& w : kWeights)
    for (const Tri& t : all) {
      const Point2 p{w[0] * t.a.x + w[1] * t.b.x + w[2] * t.c.x, w[0] * t.a.y + w[1] * t.b.y + w[2] * t.c.y};
      if (side_of(poly, p) != Side::In) continue;
      out.push_back(p);
      if (out.size() >= max_points) return out;
    }
  return out;
}

PieceDecision decide_piece(GEOSContextHandle_t h, const GEOSGeometry* piece, const PolygonIndex& input,
                           const PolygonIndex& ours, const PolygonIndex& geos, double w) {
  PieceDecision d, near;
  bool noise = false, geos_wrong = false, near_wrong = false;
  for (const Point2& p : interior_points(h, piece)) {
    const Side t = input.side(p), o = ours.side(p), g = geos.side(p);
    if (t == Side::On || o == Side::On || g == Side::On) continue;
    if (o == g) {
      noise = true;
      continue;
    }
    if (o != t) {
      if (!near_wrong && input.near_edge(p, w)) {
        near_wrong = true;
        near.witness = p;
        near.input_covers = t == Side::In;
        continue;
      }
      if (near_wrong && input.near_edge(p, w)) continue;
      d.decision = Decision::OursWrong;  // ours wrong away from the input's edges: that decides the piece
      d.witness = p;
      d.input_covers = t == Side::In;
      return d;
    }
    if (!geos_wrong) {
      geos_wrong = true;
      d.witness = p;
      d.input_covers = t == Side::In;
    }
  }
  if (geos_wrong) {
    d.decision = Decision::GeosWrong;
    return d;
  }
  if (near_wrong) {
    near.decision = Decision::OursBelowPitch;
    return near;
  }
  d.decision = noise ? Decision::Noise : Decision::Undecided;
  return d;
}

Side ring_inside(GEOSContextHandle_t h, const Ring& r, const PolygonIndex& index, const PolygonIndex& own,
                 Point2* where) {
  GeomPtr g(make_polygon(h, Polygon{r, {}}), GeomDeleter{h});
  if (!g) return Side::On;
  for (const Point2& p : interior_points(h, g.get(), 24)) {
    if (own.side(p) != Side::Out) continue;  // on an island inside the hole, or on an edge
    const Side s = index.side(p);
    if (s == Side::On) continue;
    if (where) *where = p;
    return s;
  }
  return Side::On;
}

bool piece_narrower_than(GEOSContextHandle_t h, const GEOSGeometry* piece, double w) {
  Polygon p = polygon_from(h, piece);
  double minx = INFINITY, miny = INFINITY, maxabs = 0;
  for (const Point2& q : p.outer) {
    minx = std::min(minx, q.x), miny = std::min(miny, q.y);
    maxabs = std::max({maxabs, std::fabs(q.x), std::fabs(q.y)});
  }
  const Point2 o = maxabs > 1024 && std::isfinite(minx) ? Point2{std::floor(minx), std::floor(miny)} : Point2{0, 0};
  auto move = [&](Ring& r) {
    for (Point2& q : r) q = {q.x - o.x, q.y - o.y};
  };
  move(p.outer);
  for (Ring& r : p.holes) move(r);
  GeomPtr g(make_polygon(h, p), GeomDeleter{h});
  return g && narrower_than(h, g.get(), w);
}

}  // namespace groundplan::gis::detail

// SPDX-License-Identifier: MIT
// The footprint against the building's lowest horizontal faces (see ground_check.h).
#include "footprint/ground_check.h"

#include <groundplan/ring_normal.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace groundplan::footprint {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Box {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  void add(double x, double y) { x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y); }
  bool has(double x, double y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

/// Crossing-number parity of (x, y) against a ring of the mesh (plan view).
bool ring_parity(const Mesh& m, std::uint32_t r, double x, double y, bool in) {
  const std::uint32_t a = m.ring_offsets[r], b = m.ring_offsets[r + 1];
  for (std::uint32_t i = a, j = b - 1; i < b; j = i++) {
    const Point3 &p = m.vertices[m.indices[i]], &q = m.vertices[m.indices[j]];
    if ((p.y > y) != (q.y > y) && x < p.x + (y - p.y) * (q.x - p.x) / (q.y - p.y)) in = !in;
  }
  return in;
}

bool in_ring(const Ring& r, double x, double y, bool in) {
  for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) {
    const Point2 &p = r[i], &q = r[j];
    if ((p.y > y) != (q.y > y) && x < p.x + (y - p.y) * (q.x - p.x) / (q.y - p.y)) in = !in;
  }
  return in;
}

double ring_area(const Ring& r) {
  double a = 0;
  for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) a += (r[j].x - r[i].x) * (r[j].y + r[i].y);
  return a / 2;
}

}  // namespace

std::string GroundCheck::reason() const {
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "the footprint (%.1f m2) leaves out %.1f m2 of ground under the building's lowest horizontal faces "
                "(within %.2g m of its lowest point, z %.2f): ground the building stands on",
                footprint_m2, uncovered_m2, level_m, zmin);
  return buf;
}

GroundCheck check_ground(const Mesh& mesh, const std::vector<Polygon>& footprint, const FootprintParams& params) {
  GroundCheck g;
  std::vector<Box> boxes(footprint.size());
  for (std::size_t i = 0; i < footprint.size(); ++i) {
    const Polygon& p = footprint[i];
    if (p.outer.size() < 3) continue;
    g.footprint_m2 += std::fabs(ring_area(p.outer));
    for (const Ring& h : p.holes)
      if (h.size() >= 3) g.footprint_m2 -= std::fabs(ring_area(h));
    for (const Point2& q : p.outer) boxes[i].add(q.x, q.y);
  }
  auto covered = [&](double x, double y) {
    for (std::size_t i = 0; i < footprint.size(); ++i) {
      if (!boxes[i].has(x, y)) continue;
      const Polygon& p = footprint[i];
      bool in = in_ring(p.outer, x, y, false);
      for (const Ring& h : p.holes)
        if (h.size() >= 3) in = in_ring(h, x, y, in);
      if (in) return true;
    }
    return false;
  };
  g.zmin = std::numeric_limits<double>::infinity();
  for (const Point3& p : mesh.vertices)
    if (std::isfinite(p.z)) g.zmin = std::min(g.zmin, p.z);
  if (!std::isfinite(g.zmin)) return g;
  const double cos_tol = std::cos(params.horizontal_tolerance_deg * kPi / 180.0);
  // Where a thin slab lies low, its top and its bottom are both lowest faces over the same ground: a triangle
  // left out counts once, where no other one left out already covers its centroid.
  struct Out {
    Point2 a, b, c;
  };
  std::vector<Out> left_out;
  auto in_tri = [](const Out& t, double x, double y) {
    auto side = [&](const Point2& p, const Point2& q) { return (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x); };
    const double d0 = side(t.a, t.b), d1 = side(t.b, t.c), d2 = side(t.c, t.a);
    return (d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0);
  };
  g.level_m = params.level_tolerance_m;
  const double top = g.zmin + params.level_tolerance_m;
  for (const MeshFace& f : mesh.faces) {
    if (f.ring_count == 0 || f.kind == SurfaceKind::FootPrint || f.kind == SurfaceKind::RoofEdge) continue;
    const std::uint32_t a = mesh.ring_offsets[f.first_ring], b = mesh.ring_offsets[f.first_ring + 1];
    if (b - a < 3) continue;
    // Lowest: every corner within the level tolerance of the lowest point (most faces fail at once).
    bool low = true;
    for (std::uint32_t k = a; k < b && low; ++k) low = mesh.vertices[mesh.indices[k]].z <= top;
    if (!low) continue;
    // Horizontal: Newell's normal about the first corner.
    const Point3 o = mesh.vertices[mesh.indices[a]];
    const Point3 n = ring_normal(mesh, f.first_ring);
    const double nx = n.x, ny = n.y, nz = n.z;
    const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (!(len > 0) || std::fabs(nz) < cos_tol * len) continue;
    const double sign = nz > 0 ? 1 : -1;  // the outer ring's turn in plan
    g.lowest_m2 += std::fabs(nz) / 2;
    for (std::uint32_t r = f.first_ring + 1; r < f.first_ring + f.ring_count; ++r) {  // less the holes
      double h = 0;
      for (std::uint32_t i = mesh.ring_offsets[r], e = mesh.ring_offsets[r + 1], j = e - 1; i < e; j = i++) {
        const Point3 &p = mesh.vertices[mesh.indices[i]], &q = mesh.vertices[mesh.indices[j]];
        h += (q.x - p.x) * (q.y + p.y - 2 * o.y);
      }
      g.lowest_m2 -= std::fabs(h) / 2;
    }
    // The fan's triangles whose centroid lies in the face and outside the footprint: their signed area (a
    // concave face's fan triangles outside it cancel where they overlap).
    double out = 0;
    for (std::uint32_t k = a + 1; k + 1 < b; ++k) {
      const Point3 &p = mesh.vertices[mesh.indices[k]], &q = mesh.vertices[mesh.indices[k + 1]];
      const double t = ((p.x - o.x) * (q.y - o.y) - (q.x - o.x) * (p.y - o.y)) / 2;
      if (t == 0) continue;
      const double cx = (o.x + p.x + q.x) / 3, cy = (o.y + p.y + q.y) / 3;
      if (covered(cx, cy)) continue;
      bool in = ring_parity(mesh, f.first_ring, cx, cy, false);
      for (std::uint32_t r = f.first_ring + 1; r < f.first_ring + f.ring_count; ++r) in = ring_parity(mesh, r, cx, cy, in);
      if (!in || std::any_of(left_out.begin(), left_out.end(), [&](const Out& u) { return in_tri(u, cx, cy); })) continue;
      out += t * sign;
      left_out.push_back({{o.x, o.y}, {p.x, p.y}, {q.x, q.y}});
    }
    g.uncovered_m2 += std::max(out, 0.0);
  }
  return g;
}

}  // namespace groundplan::footprint

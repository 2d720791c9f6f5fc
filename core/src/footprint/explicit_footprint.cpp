// SPDX-License-Identifier: MIT
// Explicit footprints (DESIGN.md stage 3, issue 6): what the source says outright, in this order:
// GroundSurface faces, lod0FootPrint faces, the bottom of an LoD1/LoD2 solid or closed
// multi-surface. Decomposition (paper §4) is issue 5: footprint/decompose.cpp.
#include <groundplan/footprint.h>

#include "footprint/decompose.h"
#include "footprint/ground_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace groundplan {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

/// Vertex k of ring r, relative to `o` (large UTM coordinates lose digits in products otherwise).
inline Vec3 at(const Mesh& m, std::uint32_t k, const Point3& o) {
  const Point3& p = m.vertices[m.indices[k]];
  return {p.x - o.x, p.y - o.y, p.z - o.z};
}

/// Newell's normal of ring r (length = 2 x area of the ring projected on its plane).
Vec3 newell(const Mesh& m, std::uint32_t r, const Point3& o) {
  Vec3 n;
  const std::uint32_t a = m.ring_offsets[r], b = m.ring_offsets[r + 1];
  for (std::uint32_t k = a; k < b; ++k) {
    Vec3 p = at(m, k, o), q = at(m, k + 1 < b ? k + 1 : a, o);
    n.x += (p.y - q.y) * (p.z + q.z);
    n.y += (p.z - q.z) * (p.x + q.x);
    n.z += (p.x - q.x) * (p.y + q.y);
  }
  return n;
}

/// Signed volume contribution of ring r (fan from its first vertex), relative to `o`.
double ring_volume(const Mesh& m, std::uint32_t r, const Point3& o) {
  const std::uint32_t a = m.ring_offsets[r], b = m.ring_offsets[r + 1];
  if (b - a < 3) return 0;
  Vec3 p0 = at(m, a, o);
  double v = 0;
  for (std::uint32_t k = a + 1; k + 1 < b; ++k) {
    Vec3 p1 = at(m, k, o), p2 = at(m, k + 1, o);
    v += p0.x * (p1.y * p2.z - p1.z * p2.y) - p0.y * (p1.x * p2.z - p1.z * p2.x) + p0.z * (p1.x * p2.y - p1.y * p2.x);
  }
  return v / 6.0;
}

Ring ring_2d(const Mesh& m, std::uint32_t r) {
  Ring out;
  out.reserve(m.ring_offsets[r + 1] - m.ring_offsets[r]);
  for (std::uint32_t k = m.ring_offsets[r]; k < m.ring_offsets[r + 1]; ++k) {
    const Point3& p = m.vertices[m.indices[k]];
    out.push_back(Point2{p.x, p.y});
  }
  return out;
}

/// An upper bound of the area the ring covers by the even-odd rule: the sum of the unsigned areas of
/// its fan triangles from the first vertex. (A point of odd parity has an odd, so nonzero, winding
/// number, which is the sum of the fan triangles' signed indicators: some triangle covers it.) Unlike
/// the signed area it is not cancelled by a self-crossing ring: a symmetric bow-tie has signed area 0
/// but two triangles of area, which the union keeps (issue 20: a self-crossing ring is a footprint,
/// its region what GEOS MakeValid makes of it). A wall seen edge-on still bounds to ~0.
double even_odd_area_bound(const Ring& r) {
  if (r.size() < 3) return 0;
  const Point2 o = r[0];
  double a = 0;
  for (std::size_t k = 1; k + 1 < r.size(); ++k)
    a += std::fabs((r[k].x - o.x) * (r[k + 1].y - o.y) - (r[k + 1].x - o.x) * (r[k].y - o.y));
  return a / 2;
}

/// Adds face f as a 2D polygon (holes kept) when its projected outer ring may have area. Returns whether.
bool add_face_2d(const Mesh& m, const MeshFace& f, double min_area, std::vector<Polygon>& out) {
  if (f.ring_count == 0) return false;
  Polygon poly;
  poly.outer = ring_2d(m, f.first_ring);
  if (even_odd_area_bound(poly.outer) < min_area) return false;  // NaN is kept: the union names it
  for (std::uint32_t r = f.first_ring + 1; r < f.first_ring + f.ring_count; ++r) {
    Ring h = ring_2d(m, r);
    if (even_odd_area_bound(h) >= min_area) poly.holes.push_back(std::move(h));
  }
  out.push_back(std::move(poly));
  return true;
}

/// Footprint by surface decomposition (issue 5) into `res`; false with `why` when none was found.
bool decompose_into(const Mesh& mesh, const FootprintParams& params, FootprintResult& res, std::string& why) {
  footprint::DecomposeParams dp;
  dp.proxy_tolerance_deg = params.proxy_tolerance_deg;
  dp.weld_tolerance_m = params.weld_tolerance_m;
  dp.min_loop_area_m2 = params.min_face_area_m2;
  footprint::DecomposeResult d = footprint::decompose_footprint(mesh, dp);
  if (!d.polygons.empty()) {
    res.footprint.polygons = std::move(d.polygons);
    res.ok = true;
    res.method = d.stats.shadow ? FootprintMethod::DecompositionShadow : FootprintMethod::Decomposition;
    // Not trusted: the lowest horizontal faces must lie inside it (ground_check.h).
    const footprint::GroundCheck g = footprint::check_ground(mesh, res.footprint.polygons, params);
    if (g.misses_ground()) res.misses_ground = g.reason();
    if (d.stats.shadow) {
      // Issue 21: say why the wall loops were not taken (the shadow also covers every overhang).
      char buf[400];
      if (d.stats.loops == 0)
        std::snprintf(buf, sizeof buf,
                      "footprint is the shadow: the walls' lower boundary closed no loop (%zu lower-boundary edges, "
                      "%zu chains that do not close)", d.stats.footprint_edges, d.stats.open_chains);
      else
        std::snprintf(buf, sizeof buf,
                      "footprint is the shadow: %.1f m of the walls' lower boundary (%.1f m in all) lies in %zu chains "
                      "that do not close, outside the %zu loops and no higher (a model that is not watertight)",
                      d.stats.open_outside_m, d.stats.lower_boundary_m, d.stats.open_chains, d.stats.loops);
      res.note = buf;
    } else if (d.stats.closed_in_plan) {
      // Issue 21: the walls' footprint, though their lower boundary closed only in plan across gaps.
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "footprint closed in plan, not the shadow: the walls' lower boundary (%.1f m) leaves %zu chains "
                    "open beside %zu loops; joined in plan where their ends lie within %.2f m, %.1f m of it enclose "
                    "the footprint",
                    d.stats.lower_boundary_m, d.stats.open_chains, d.stats.loops, d.stats.plan_gap_m, d.stats.plan_kept_m);
      res.note = buf;
    }
    return true;
  }
  why = "surface decomposition found no closed lower wall boundary (" + std::to_string(d.stats.faces_used) +
        " usable faces, " + std::to_string(d.stats.footprint_edges) + " lower-boundary edges, " +
        std::to_string(d.stats.open_chains) + " chains that do not close)";
  return false;
}

const char* kind_name(SurfaceKind k) {
  switch (k) {
    case SurfaceKind::Ground: return "GroundSurface";
    case SurfaceKind::FootPrint: return "lod0FootPrint";
    default: return "";
  }
}

}  // namespace

const char* to_string(FootprintMethod method) {
  switch (method) {
    case FootprintMethod::None: return "none";
    case FootprintMethod::GroundSurface: return "ground-surface";
    case FootprintMethod::FootPrint: return "lod0-footprint";
    case FootprintMethod::SolidBottom: return "solid-bottom";
    case FootprintMethod::Decomposition: return "decomposition";
    case FootprintMethod::DecompositionShadow: return "decomposition-shadow";
  }
  return "?";
}

FootprintResult make_footprint(const Mesh& mesh, const FootprintParams& params) {
  FootprintResult res;
  Footprint& fp = res.footprint;
  fp.source_id = mesh.source_id;
  fp.parent_id = mesh.parent_id;
  fp.source_file = mesh.source_file;
  if (mesh.faces.empty() || mesh.vertices.empty()) {
    res.code = "EMPTY_MESH";
    res.reason = "the building has no faces";
    return res;
  }
  fp.min_z = std::numeric_limits<double>::infinity();
  fp.max_z = -fp.min_z;
  for (const Point3& p : mesh.vertices) {
    fp.min_z = std::min(fp.min_z, p.z);
    fp.max_z = std::max(fp.max_z, p.z);
  }
  if (params.source == FootprintSource::Decompose) {
    std::string why;
    if (!decompose_into(mesh, params, res, why)) {
      res.code = "NO_FOOTPRINT_LOOP";
      res.reason = why;
    }
    return res;
  }

  // 1. and 2.: faces the source calls ground (GroundSurface), else footprint (lod0FootPrint).
  for (SurfaceKind kind : {SurfaceKind::Ground, SurfaceKind::FootPrint}) {
    std::size_t tagged = 0;
    for (const MeshFace& f : mesh.faces) {
      if (f.kind != kind) continue;
      ++tagged;
      add_face_2d(mesh, f, params.min_face_area_m2, fp.polygons);
    }
    if (!fp.polygons.empty()) {
      res.ok = true;
      res.method = kind == SurfaceKind::Ground ? FootprintMethod::GroundSurface : FootprintMethod::FootPrint;
      return res;
    }
    (void)tagged;
  }

  // 3.: the bottom of a solid / closed multi-surface. Roofs and lod0 outlines are never bottoms.
  auto usable = [](const MeshFace& f) {
    return f.kind != SurfaceKind::Roof && f.kind != SurfaceKind::RoofEdge && f.kind != SurfaceKind::FootPrint;
  };
  const Point3 o = mesh.vertices[0];
  const double cos_tol = std::cos(params.horizontal_tolerance_deg * kPi / 180.0);
  double volume = 0, area_sum = 0, zmin = std::numeric_limits<double>::infinity();
  struct Cand {
    std::uint32_t face;
    double nz;        // unit normal's z as written
    double zlo, zhi;  // outer ring's z range
    double plan_m2;   // outer ring's area in plan
  };
  std::vector<Cand> horizontal;
  for (std::uint32_t i = 0; i < mesh.faces.size(); ++i) {
    const MeshFace& f = mesh.faces[i];
    if (f.ring_count == 0) continue;
    // The volume includes roofs (a closed solid needs them) but not lod0 outlines.
    if (f.kind != SurfaceKind::RoofEdge && f.kind != SurfaceKind::FootPrint)
      for (std::uint32_t r = f.first_ring; r < f.first_ring + f.ring_count; ++r) volume += ring_volume(mesh, r, o);
    if (!usable(f)) continue;
    Vec3 n = newell(mesh, f.first_ring, o);
    double len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    if (len <= 0) continue;
    area_sum += len / 2;
    double zlo = std::numeric_limits<double>::infinity(), zhi = -zlo;
    for (std::uint32_t k = mesh.ring_offsets[f.first_ring]; k < mesh.ring_offsets[f.first_ring + 1]; ++k) {
      double z = mesh.vertices[mesh.indices[k]].z;
      zlo = std::min(zlo, z);
      zhi = std::max(zhi, z);
    }
    zmin = std::min(zmin, zlo);
    if (std::fabs(n.z) >= cos_tol * len) horizontal.push_back(Cand{i, n.z / len, zlo, zhi, std::fabs(n.z) / 2});
  }
  // Orientation: outward when the signed volume is positive. Files are not consistent (inward
  // shells, bags of polygons); a volume that is tiny against area^1.5 says nothing.
  const double scale = std::pow(std::max(area_sum, 1e-12), 1.5);
  const int outward = std::fabs(volume) > 1e-3 * scale ? (volume > 0 ? 1 : -1) : 0;

  std::vector<const Cand*> bottom, bottom_down;
  double down_m2 = 0, up_m2 = 0;
  for (const Cand& c : horizontal) {
    if (c.zhi > zmin + params.level_tolerance_m) continue;
    bottom.push_back(&c);
    if (outward != 0 && c.nz * outward < 0) {
      bottom_down.push_back(&c);
      down_m2 += c.plan_m2;
    } else {
      up_m2 += c.plan_m2;
    }
  }
  // Down-facing faces at the lowest level are the bottom (an up-facing one there is the top of something
  // low: a slab, a plinth, a floor outside the solid). In a closed solid whose faces all turn the same way,
  // every up-facing face at the lowest level has down-facing ones below it, so the down-facing ones cover
  // at least as much plan as the up-facing ones. Where they cover less, the faces' turns say nothing: the
  // bottom is turned inward unlike the walls (a bag of polygons, an inconsistent export), or its turn is
  // noise (quantised positions flip slivers of a few square centimetres over, and taking those alone lost a
  // whole building's ground). Then, as when none faces down, every face at the lowest level is the bottom.
  const auto& chosen = down_m2 >= up_m2 && !bottom_down.empty() ? bottom_down : bottom;
  for (const Cand* c : chosen) add_face_2d(mesh, mesh.faces[c->face], params.min_face_area_m2, fp.polygons);
  if (!fp.polygons.empty()) {
    res.ok = true;
    res.method = FootprintMethod::SolidBottom;
    // Chosen among the lowest horizontal faces by their turn: those left out must lie over the chosen ones.
    const footprint::GroundCheck g = footprint::check_ground(mesh, fp.polygons, params);
    if (g.misses_ground()) res.misses_ground = g.reason();
    return res;
  }

  res.code = "NO_GROUND_GEOMETRY";
  std::size_t roof_edges = 0;
  for (const MeshFace& f : mesh.faces) roof_edges += f.kind == SurfaceKind::RoofEdge;
  if (roof_edges == mesh.faces.size()) {
    res.reason = "the building has only lod0RoofEdge geometry (a roof outline, not a footprint)";
  } else if (horizontal.empty()) {
    res.reason = "no GroundSurface, no lod0FootPrint, and none of its " + std::to_string(mesh.faces.size()) +
                 " faces is horizontal within " + std::to_string(params.horizontal_tolerance_deg) + " degrees";
  } else {
    res.reason = "no GroundSurface, no lod0FootPrint, and no horizontal face lies at the building's lowest level "
                 "(within " + std::to_string(params.level_tolerance_m) + " m of z = " + std::to_string(zmin) + ")";
  }
  // Auto: no explicit ground geometry, so decomposition (issue 5).
  if (params.source == FootprintSource::Auto) {
    std::string why;
    if (decompose_into(mesh, params, res, why)) {
      if (!res.note.empty()) res.note = res.reason + "; " + res.note;  // the explicit route's failure first
      res.code.clear();
      res.reason.clear();
      return res;
    }
    res.reason += "; " + why;
  }
  (void)kind_name;
  return res;
}

}  // namespace groundplan

// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 4b, contacts: parts that touch
// without sharing edges (issue 21).
//
// SketchUp / Google Earth models are built of parts laid on each other: a roof slab on walls whose
// tops end inside the slab's underside, a storey or a component set on a roof, a balcony slab whose
// back lies in a wall. Such parts share no edge, so stages 2 to 4 see separate parts, each with a
// lower boundary of its own (the slab's underside, the upper box's bottom), which are no local
// minima of the building. Where an edge of one part lies in a face of another (within the weld
// tolerance: both ends on the face's plane, the midpoint on the face), the decomposition now sees
// them meet, as if that face were split along the edge:
//  (a) a wall's top edge (the wall goes down from it) on a floor facet: the floor hangs, like a
//      soffit (a slab roof on walls, a box set on a lower one that it overhangs);
//  (b) a lower-boundary edge of the walls on a ceiling facet: the walls stand on a roof (a box set
//      on another), a ceiling boundary as in the paper, so no footprint edge.
//  (c) a floor facet's edge on a wall facet that goes on below it (a balcony slab against a wall):
//      the floor hangs when it lies higher above the bottom of the part it leans on than its own part
//      reaches above it. A building part on slightly higher ground beside a taller one looks the same
//      but for the heights: it stands 0.5 m up and rises 8 m (Berlin LoD2 sample), where a balcony
//      slab stands 3 m up and is 0.2 m thick.
// Only between different parts (components): one part's own faces already share their edges.
// Holes of the touched face are not looked at (an edge over a hole counts as on the face).
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>

namespace groundplan::footprint::detail {

void Decomposer::project_faces() {
  const std::size_t nf = ws_.faces.size();
  auto& start = ws_.face_pts_start;
  auto& pts = ws_.face_pts;
  start.assign(nf + 1, 0);
  pts.clear();
  for (std::uint32_t f = 0; f < nf; ++f) {
    start[f] = static_cast<std::uint32_t>(pts.size());
    const FaceInfo& fi = ws_.faces[f];
    if (fi.cls == kSkipped || !(fi.len > 0)) continue;
    if (!welded_ring(m_.faces[f].first_ring) || ws_.ring_tmp.size() < 3) continue;
    // Project along the normal's largest component.
    const double ax = std::fabs(fi.n.x), ay = std::fabs(fi.n.y), az = std::fabs(fi.n.z);
    for (std::uint32_t v : ws_.ring_tmp) {
      const V3& p = ws_.wpos[v];
      pts.push_back(az >= ax && az >= ay ? Point2{p.x, p.y} : ay >= ax ? Point2{p.x, p.z} : Point2{p.y, p.z});
    }
  }
  start[nf] = static_cast<std::uint32_t>(pts.size());
}

bool Decomposer::edge_on_face(std::uint32_t f, const V3& p, const V3& q) const {
  const FaceInfo& fi = ws_.faces[f];
  const double t = tol_;
  if (std::min(p.x, q.x) > fi.hi.x + t || std::max(p.x, q.x) < fi.lo.x - t || std::min(p.y, q.y) > fi.hi.y + t ||
      std::max(p.y, q.y) < fi.lo.y - t || std::min(p.z, q.z) > fi.hi.z + t || std::max(p.z, q.z) < fi.lo.z - t)
    return false;
  const std::uint32_t s = ws_.face_pts_start[f], e = ws_.face_pts_start[f + 1];
  if (e - s < 3) return false;
  const double lim = t * fi.len;  // |n . d| / |n| <= tol
  if (std::fabs(dot(fi.n, p - fi.c)) > lim || std::fabs(dot(fi.n, q - fi.c)) > lim) return false;
  const V3 m{(p.x + q.x) / 2, (p.y + q.y) / 2, (p.z + q.z) / 2};
  const double ax = std::fabs(fi.n.x), ay = std::fabs(fi.n.y), az = std::fabs(fi.n.z);
  const Point2 mp = az >= ax && az >= ay ? Point2{m.x, m.y} : ay >= ax ? Point2{m.x, m.z} : Point2{m.y, m.z};
  const Point2* ring = ws_.face_pts.data() + s;
  const std::size_t n = e - s;
  if (inside(ring, n, mp)) return true;
  // On the boundary, within the tolerance.
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const double dx = ring[i].x - ring[j].x, dy = ring[i].y - ring[j].y;
    const double l2 = dx * dx + dy * dy;
    double u = l2 > 0 ? ((mp.x - ring[j].x) * dx + (mp.y - ring[j].y) * dy) / l2 : 0;
    u = std::clamp(u, 0.0, 1.0);
    const double ex = ring[j].x + u * dx - mp.x, ey = ring[j].y + u * dy - mp.y;
    if (ex * ex + ey * ey <= tol2_) return true;
  }
  return false;
}

void Decomposer::find_contacts() {
  ws_.on_roof.assign(ws_.group_count.size(), 0);
  if (ncomp_ < 2) return;
  bool any_floor = false, any_ceiling = false;
  for (const FaceInfo& fi : ws_.faces) any_floor |= fi.cls == kFloor, any_ceiling |= fi.cls == kCeiling;
  if (!any_floor && !any_ceiling) return;
  project_faces();
  const std::size_t nf = ws_.faces.size(), ng = ws_.group_count.size();
  auto& par = ws_.floor_uf;
  auto root = [&](std::uint32_t x) {
    while (par[x] != x) x = par[x];
    return x;
  };
  bool hung = false;
  for (std::size_t g = 0; g < ng; ++g) {
    const std::uint32_t s = ws_.group_start[g], c = ws_.group_count[g];
    bool wall_down = false, wall_up = false, floor = false, floor_hanging = false, ceiling = false;
    std::uint32_t any = kNone;
    for (std::uint32_t i = 0; i < c; ++i) {
      const HalfEdge& h = ws_.halfedges[ws_.group_members[s + i]];
      const FaceInfo& fi = ws_.faces[h.face];
      if (fi.cls == kSkipped) continue;
      any = h.face;
      if (fi.cls == kWall) (h.up < 0 ? wall_down : wall_up) |= h.up != 0;
      if (fi.cls == kCeiling) ceiling = true;
      if (fi.cls == kFloor) floor = true, floor_hanging |= ws_.hanging[h.face] != 0;
    }
    if (any == kNone) continue;
    const HalfEdge& h0 = ws_.halfedges[ws_.group_members[s]];
    const V3 &p = ws_.wpos[h0.a], &q = ws_.wpos[h0.b];
    const std::uint32_t comp = ws_.face_comp[any];
    const bool rule_a = wall_down && !floor;
    const bool rule_b = wall_up && !wall_down && !ceiling && !floor_hanging;
    const bool rule_c = floor && !floor_hanging && !wall_down;
    if (!rule_a && !rule_b && !rule_c) continue;
    const double z_edge = std::min(p.z, q.z);
    for (std::uint32_t f = 0; f < nf; ++f) {
      const FaceInfo& fi = ws_.faces[f];
      if (ws_.face_comp[f] == comp) continue;
      if (rule_a && fi.cls == kFloor && !ws_.hanging[f] && edge_on_face(f, p, q)) {
        ws_.hanging[root(f)] = 1, ws_.hanging[f] = 1, hung = true;
        ++stats_->contacts;
      } else if (rule_b && fi.cls == kCeiling && edge_on_face(f, p, q)) {
        ws_.on_roof[g] = 1;
        ++stats_->contacts;
        break;
      } else if (rule_c && fi.cls == kWall && fi.lo.z < z_edge - tol_ &&
                 z_edge - ws_.comp_lo[ws_.face_comp[f]].z > ws_.comp_hi[comp].z - std::max(p.z, q.z) &&
                 edge_on_face(f, p, q)) {
        for (std::uint32_t i = 0; i < c; ++i) {
          const HalfEdge& h = ws_.halfedges[ws_.group_members[s + i]];
          if (ws_.faces[h.face].cls == kFloor) ws_.hanging[root(h.face)] = 1, ws_.hanging[h.face] = 1;
        }
        hung = true;
        ++stats_->contacts;
        break;
      }
    }
  }
  if (hung)
    for (std::uint32_t f = 0; f < nf; ++f)
      if (ws_.faces[f].cls == kFloor && ws_.hanging[root(f)]) ws_.hanging[f] = 1;
}

}  // namespace groundplan::footprint::detail

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
#include <limits>

namespace groundplan::footprint::detail {

const Point2* Decomposer::projected_face(std::uint32_t f, std::size_t& n) {
  auto& at = ws_.face_pts_at;
  auto& pts = ws_.face_pts;
  if (at[f] == kNone) {
    at[f] = static_cast<std::uint32_t>(pts.size());
    ws_.face_pts_n[f] = 0;
    const FaceInfo& fi = ws_.faces[f];
    if (welded_ring(m_.faces[f].first_ring) && ws_.ring_tmp.size() >= 3) {
      // Project along the normal's largest component.
      const double ax = std::fabs(fi.n.x), ay = std::fabs(fi.n.y), az = std::fabs(fi.n.z);
      for (std::uint32_t v : ws_.ring_tmp) {
        const V3& p = ws_.wpos[v];
        pts.push_back(az >= ax && az >= ay ? Point2{p.x, p.y} : ay >= ax ? Point2{p.x, p.z} : Point2{p.y, p.z});
      }
      ws_.face_pts_n[f] = static_cast<std::uint32_t>(ws_.ring_tmp.size());
    }
  }
  n = ws_.face_pts_n[f];
  return pts.data() + at[f];
}

void Decomposer::index_faces() {
  auto& G = ws_.grid;
  const std::size_t nf = ws_.faces.size();
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  std::size_t used = 0;
  auto usable = [&](const FaceInfo& fi) { return fi.cls != kSkipped && fi.len > 0; };
  for (const FaceInfo& fi : ws_.faces)
    if (usable(fi)) x0 = std::min(x0, fi.lo.x), y0 = std::min(y0, fi.lo.y), x1 = std::max(x1, fi.hi.x), y1 = std::max(y1, fi.hi.y), ++used;
  G.n = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(used))), 1, 64);
  G.x0 = x0, G.y0 = y0;
  G.sx = G.n / std::max(x1 - x0, 1e-9), G.sy = G.n / std::max(y1 - y0, 1e-9);
  const std::size_t cells = static_cast<std::size_t>(G.n) * G.n;
  auto cx = [&](double x) { return std::clamp(static_cast<int>((x - G.x0) * G.sx), 0, G.n - 1); };
  auto cy = [&](double y) { return std::clamp(static_cast<int>((y - G.y0) * G.sy), 0, G.n - 1); };
  for (int k = 0; k < 2; ++k) G.start[k].assign(cells + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::uint32_t f = 0; f < nf; ++f) {
      const FaceInfo& fi = ws_.faces[f];
      if (!usable(fi)) continue;
      const int k = fi.cls == kWall;
      auto& start = G.start[k];
      for (int j = cy(fi.lo.y), j1 = cy(fi.hi.y); j <= j1; ++j)
        for (int i = cx(fi.lo.x), i1 = cx(fi.hi.x); i <= i1; ++i) {
          const std::size_t c = static_cast<std::size_t>(j) * G.n + i;
          if (pass == 0) ++start[c + 1];
          else G.faces[k][start[c]++] = f;  // start[c] used as the cursor, restored below
        }
    }
    for (int k = 0; k < 2; ++k) {
      auto& start = G.start[k];
      if (pass == 0) {
        for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
        G.faces[k].resize(start[cells]);
      } else {
        for (std::size_t c = cells; c > 0; --c) start[c] = start[c - 1];
        start[0] = 0;
      }
    }
  }
  G.stamp.assign(nf, 0);
  G.gen = 0;
}

void Decomposer::faces_near(const V3& p, const V3& q, bool walls) {
  auto& G = ws_.grid;
  G.near.clear();
  ++G.gen;
  auto cx = [&](double x) { return std::clamp(static_cast<int>((x - G.x0) * G.sx), 0, G.n - 1); };
  auto cy = [&](double y) { return std::clamp(static_cast<int>((y - G.y0) * G.sy), 0, G.n - 1); };
  const int i0 = cx(std::min(p.x, q.x) - tol_), i1 = cx(std::max(p.x, q.x) + tol_);
  const int j0 = cy(std::min(p.y, q.y) - tol_), j1 = cy(std::max(p.y, q.y) + tol_);
  for (int k = 0; k <= int(walls); ++k)
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const std::size_t c = static_cast<std::size_t>(j) * G.n + i;
        for (std::uint32_t e = G.start[k][c]; e < G.start[k][c + 1]; ++e) {
          const std::uint32_t f = G.faces[k][e];
          if (G.stamp[f] != G.gen) G.stamp[f] = G.gen, G.near.push_back(f);
        }
      }
  // Rule c stops at the first wall it finds and rule b at the first ceiling: when both may apply,
  // the face of smaller index decides, as it did when every face was tried in order.
  if (walls) std::sort(G.near.begin(), G.near.end());
}

bool Decomposer::edge_on_face(std::uint32_t f, const V3& p, const V3& q) {
  const FaceInfo& fi = ws_.faces[f];
  const double t = tol_;
  if (std::min(p.x, q.x) > fi.hi.x + t || std::max(p.x, q.x) < fi.lo.x - t || std::min(p.y, q.y) > fi.hi.y + t ||
      std::max(p.y, q.y) < fi.lo.y - t || std::min(p.z, q.z) > fi.hi.z + t || std::max(p.z, q.z) < fi.lo.z - t)
    return false;
  const double lim = t * fi.len;  // |n . d| / |n| <= tol
  if (std::fabs(dot(fi.n, p - fi.c)) > lim || std::fabs(dot(fi.n, q - fi.c)) > lim) return false;
  std::size_t n = 0;
  const Point2* ring = projected_face(f, n);
  if (n < 3) return false;
  const V3 m{(p.x + q.x) / 2, (p.y + q.y) / 2, (p.z + q.z) / 2};
  const double ax = std::fabs(fi.n.x), ay = std::fabs(fi.n.y), az = std::fabs(fi.n.z);
  const Point2 mp = az >= ax && az >= ay ? Point2{m.x, m.y} : ay >= ax ? Point2{m.x, m.z} : Point2{m.y, m.z};
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
  ws_.face_pts_at.assign(ws_.faces.size(), kNone);
  ws_.face_pts_n.resize(ws_.faces.size());
  ws_.face_pts.clear();
  index_faces();
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
    faces_near(p, q, rule_c);  // the faces whose box could hold the edge
    for (const std::uint32_t f : ws_.grid.near) {
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

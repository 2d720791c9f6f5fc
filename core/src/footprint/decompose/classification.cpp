// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 4, decomposition into floor, ceiling and wall patches.
//
//  4. Decomposition: facets within proxy_tolerance_deg of the vertical proxy normal are floor (normal
//     down) or ceiling (normal up) facets, the rest wall facets; patches are their connected sets.
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

void Decomposer::classify() {
  // Walls were told at build time; the rest face up (ceiling) or down (floor) once oriented.
  for (FaceInfo& fi : ws_.faces)
    if (fi.cls == kFloor || fi.cls == kCeiling) fi.cls = fi.sign * fi.n.z > 0 ? kCeiling : kFloor;
}

/// Floor patches from whose boundary a wall goes down are soffits (the underside of an upper
/// storey wider than the one below), not ground: walls rising from them are no footprint, or a
/// storey overhanging on every side would give its shadow. Unless the patch reaches out much further
/// than the walls drop (kStepDepthPerDrop): then it is the ground's upper step on a slope and the wall
/// going down is the riser (step_floor). hanging[f] and step_floor[f] for floor facets.
void Decomposer::find_hanging_floors() {
  const std::size_t nf = ws_.faces.size();
  auto& par = ws_.floor_uf;
  par.resize(nf);
  ws_.hanging.assign(nf, 0);
  ws_.step_floor.assign(nf, 0);
  bool any = false;
  for (std::uint32_t f = 0; f < nf; ++f) {
    par[f] = f;
    any |= ws_.faces[f].cls == kFloor;
  }
  if (!any) return;
  auto find = [&](std::uint32_t x) {
    while (par[x] != x) x = par[x] = par[par[x]];
    return x;
  };
  const std::size_t ng = ws_.group_count.size();
  bool any_down = false;
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t g = 0; g < ng; ++g) {
      const std::uint32_t s = ws_.group_start[g], c = ws_.group_count[g];
      std::uint32_t first_floor = kNone;
      bool down = false;
      double wall_lo = std::numeric_limits<double>::infinity();  // lowest z of the walls going down
      for (std::uint32_t i = 0; i < c; ++i) {
        const HalfEdge& h = ws_.halfedges[ws_.group_members[s + i]];
        const std::uint8_t cls = ws_.faces[h.face].cls;
        if (cls == kWall && h.up < 0) down = true, wall_lo = std::min(wall_lo, ws_.faces[h.face].lo.z);
        if (cls != kFloor) continue;
        if (pass == 0) {
          if (first_floor == kNone) first_floor = h.face;
          else par[find(h.face)] = find(first_floor);
        }
      }
      if (pass == 0 || !down) continue;
      const HalfEdge& h0 = ws_.halfedges[ws_.group_members[s]];
      const V3 &a = ws_.wpos[h0.a], &b = ws_.wpos[h0.b];
      for (std::uint32_t i = 0; i < c; ++i) {
        const HalfEdge& h = ws_.halfedges[ws_.group_members[s + i]];
        if (ws_.faces[h.face].cls != kFloor) continue;
        const std::uint32_t r = find(h.face);
        if (!any_down) {
          any_down = true;
          ws_.patch_down_len.assign(nf, 0);
          ws_.patch_drop.assign(nf, 0);
        }
        ws_.hanging[r] = 1;
        ws_.patch_down_len[r] += std::hypot(b.x - a.x, b.y - a.y);
        ws_.patch_drop[r] = std::max(ws_.patch_drop[r], std::min(a.z, b.z) - wall_lo);
        break;  // one floor facet per edge: the patch's edge counted once
      }
    }
  if (any_down) {
    // Plan area of each hanging patch, then soffit or step.
    auto& area = ws_.patch_plan_area;
    area.assign(nf, 0);
    for (std::uint32_t f = 0; f < nf; ++f)
      if (ws_.faces[f].cls == kFloor) area[find(f)] += std::fabs(ws_.faces[f].net.z) / 2;  // holes less
    for (std::uint32_t f = 0; f < nf; ++f)
      if (ws_.faces[f].cls == kFloor && par[f] == f && ws_.hanging[f] &&
          area[f] > kStepDepthPerDrop * ws_.patch_drop[f] * ws_.patch_down_len[f])
        ws_.hanging[f] = 0, ws_.step_floor[f] = 1;
  }
  for (std::uint32_t f = 0; f < nf; ++f)
    if (ws_.faces[f].cls == kFloor) {
      const std::uint32_t r = find(f);
      ws_.hanging[f] = ws_.hanging[r];
      ws_.step_floor[f] = ws_.step_floor[r];
    }
}

void Decomposer::fill_decomposition(SurfaceDecomposition& dec) {
  // Patches: facets of one class connected through shared edges. With the proxy normal fixed to
  // the vertical, the VSA growth from the lowest seeds reaches exactly these sets.
  const std::size_t nf = ws_.faces.size();
  std::vector<std::uint32_t> parent(nf);
  for (std::uint32_t f = 0; f < nf; ++f) parent[f] = f;
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  const std::size_t ng = ws_.group_count.size();
  for (std::size_t g = 0; g < ng; ++g) {
    const std::uint32_t s = ws_.group_start[g], c = ws_.group_count[g];
    for (std::uint32_t i = 0; i < c; ++i)
      for (std::uint32_t j = i + 1; j < c; ++j) {
        const std::uint32_t f1 = ws_.halfedges[ws_.group_members[s + i]].face;
        const std::uint32_t f2 = ws_.halfedges[ws_.group_members[s + j]].face;
        if (ws_.faces[f1].cls != ws_.faces[f2].cls) continue;
        const std::uint32_t r1 = find(f1), r2 = find(f2);
        if (r1 != r2) parent[std::max(r1, r2)] = std::min(r1, r2);
      }
  }
  dec = SurfaceDecomposition{};
  dec.face_patch.assign(nf, -1);
  std::vector<std::int32_t> root_patch(nf, -1);
  // Bottom-up numbering: patches in order of their lowest facet.
  std::vector<std::pair<double, std::uint32_t>> order;
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (ws_.faces[f].cls == kSkipped) continue;
    double zmin = std::numeric_limits<double>::infinity();
    const MeshFace& mf = m_.faces[f];
    for (std::uint32_t k = m_.ring_offsets[mf.first_ring]; k < m_.ring_offsets[mf.first_ring + 1]; ++k)
      zmin = std::min(zmin, m_.vertices[m_.indices[k]].z);
    order.emplace_back(zmin, f);
  }
  std::stable_sort(order.begin(), order.end());
  for (auto [z, f] : order) {
    const std::uint32_t r = find(f);
    if (root_patch[r] < 0) {
      root_patch[r] = static_cast<std::int32_t>(dec.patch_kind.size());
      const std::uint8_t cls = ws_.faces[f].cls;
      dec.patch_kind.push_back(cls == kFloor ? PatchKind::Floor : cls == kCeiling ? PatchKind::Ceiling : PatchKind::Wall);
      dec.patch_z.push_back(0);
      dec.patch_area_m2.push_back(0);
    }
    const std::int32_t pid = root_patch[r];
    dec.face_patch[f] = pid;
    // Area-weighted mean z of the facet's outer ring vertices (the proxy plane's height).
    const MeshFace& mf = m_.faces[f];
    double zs = 0;
    const std::uint32_t a = m_.ring_offsets[mf.first_ring], b = m_.ring_offsets[mf.first_ring + 1];
    for (std::uint32_t k = a; k < b; ++k) zs += m_.vertices[m_.indices[k]].z;
    const double area = ws_.faces[f].len / 2;
    dec.patch_z[pid] += area * zs / (b - a);
    dec.patch_area_m2[pid] += area;
  }
  for (std::size_t p = 0; p < dec.patch_z.size(); ++p)
    dec.patch_z[p] = dec.patch_area_m2[p] > 0 ? dec.patch_z[p] / dec.patch_area_m2[p] : 0;
}

}  // namespace groundplan::footprint::detail

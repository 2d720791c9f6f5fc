// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 3, orientation.
//
//  3. Orientation: union-find with parity over manifold edges (two facets) makes every part's facets
//     agree; the part's signed volume, taken about a point at the part's lowest z, says which way is
//     out. The volume stays meaningful with an open bottom: the missing floor lies (nearly) in a plane
//     through that point, so it would have added (nearly) nothing.
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

void Decomposer::orient() {
  FaceInfo* F = ws_.faces.data();
  const std::size_t ng = ws_.group_count.size();
  const std::uint32_t* cnt = ws_.group_count.data();
  const std::uint32_t* st = ws_.group_start.data();
  const std::uint32_t* mem = ws_.group_members.data();
  const HalfEdge* H = ws_.halfedges.data();
  std::size_t nonmanifold = 0;
  for (std::size_t g = 0; g < ng; ++g) {
    const std::uint32_t c = cnt[g];
    nonmanifold += c > 2;
    if (c != 2) continue;
    const HalfEdge& h1 = H[mem[st[g]]];
    const HalfEdge& h2 = H[mem[st[g] + 1]];
    if (h1.face == h2.face) continue;
    // Consistent neighbours run the shared edge in opposite directions.
    const std::uint8_t rel = h1.a == h2.a ? 1 : 0;
    std::uint8_t p1, p2;
    const std::uint32_t r1 = uf_find(F, h1.face, p1), r2 = uf_find(F, h2.face, p2);
    if (r1 == r2) continue;  // already joined (a conflict here means a non-orientable patch: ignored)
    F[r2].uf = r1;
    F[r2].parity = static_cast<std::uint8_t>(p1 ^ p2 ^ rel);
  }
  stats_->nonmanifold_edges += nonmanifold;
  // Dense component ids and parities, bounding boxes, then signed volumes about each part's low point.
  const std::size_t nf = ws_.faces.size();
  ws_.comp_index.assign(nf, kNone);
  ws_.face_comp.resize(nf);
  ws_.face_par.resize(nf);
  std::uint32_t* cidx = ws_.comp_index.data();
  std::uint32_t* fcomp = ws_.face_comp.data();
  std::uint8_t* fpar = ws_.face_par.data();
  ws_.comp_lo.clear();
  ws_.comp_hi.clear();
  ncomp_ = 0;
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (F[f].cls == kSkipped) {
      fcomp[f] = kNone;
      fpar[f] = 0;
      continue;
    }
    std::uint8_t par;
    const std::uint32_t r = uf_find(F, f, par);
    if (cidx[r] == kNone) {
      cidx[r] = static_cast<std::uint32_t>(ncomp_++);
      ws_.comp_lo.push_back(V3{inf, inf, inf});
      ws_.comp_hi.push_back(V3{-inf, -inf, -inf});
    }
    fcomp[f] = cidx[r];
    fpar[f] = par;
  }
  stats_->components = ncomp_;
  // Signed volume of each part about its low point org (bounding-box centre in x, y; lowest z):
  // a planar face's cone from org is (1/6) net . (c - org), net being twice its area vector (its
  // Newell normal less its holes') and c any point of it. Summed per part with the faces' parities:
  // (1/6) (sum net.c - (sum net) . org), so one pass over the faces and none over the edges.
  ws_.comp_vol.assign(ncomp_, 0);
  ws_.comp_area.assign(ncomp_, 0);
  ws_.comp_net.assign(ncomp_, V3{});
  V3* CLO = ws_.comp_lo.data();
  V3* CHI = ws_.comp_hi.data();
  double* CVOL = ws_.comp_vol.data();
  double* CAREA = ws_.comp_area.data();
  V3* CNET = ws_.comp_net.data();
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (F[f].cls == kSkipped) continue;
    const FaceInfo& fi = F[f];
    const std::uint32_t c = fcomp[f];
    V3& lo = CLO[c];
    V3& hi = CHI[c];
    lo.x = std::min(lo.x, fi.lo.x), lo.y = std::min(lo.y, fi.lo.y), lo.z = std::min(lo.z, fi.lo.z);
    hi.x = std::max(hi.x, fi.hi.x), hi.y = std::max(hi.y, fi.hi.y), hi.z = std::max(hi.z, fi.hi.z);
    CAREA[c] += fi.len / 2;
    const double s = fpar[f] ? -1.0 : 1.0;
    CVOL[c] += s * dot(fi.net, fi.c);
    V3& N = CNET[c];
    N.x += s * fi.net.x, N.y += s * fi.net.y, N.z += s * fi.net.z;
  }
  for (std::size_t c = 0; c < ncomp_; ++c) {
    const V3 org{(CLO[c].x + CHI[c].x) / 2, (CLO[c].y + CHI[c].y) / 2, CLO[c].z};
    CVOL[c] = (CVOL[c] - dot(CNET[c], org)) / 6;
  }
  ws_.comp_sign.assign(ncomp_, 0);
  std::int8_t* CS = ws_.comp_sign.data();
  for (std::size_t c = 0; c < ncomp_; ++c) {
    const double scale = std::pow(std::max(CAREA[c], 1e-12), 1.5);
    const double v = CVOL[c];
    if (std::fabs(v) > 1e-6 * scale) CS[c] = v > 0 ? 1 : -1;
    else ++stats_->unoriented_components;
  }
  std::size_t flipped = 0;
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (F[f].cls == kSkipped) continue;
    const std::int8_t cs = CS[fcomp[f]] == 0 ? 1 : CS[fcomp[f]];
    F[f].sign = static_cast<std::int8_t>(fpar[f] ? -cs : cs);
    flipped += F[f].sign < 0;
  }
  stats_->flipped_faces += flipped;
}

}  // namespace groundplan::footprint::detail

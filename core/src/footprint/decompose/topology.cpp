// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 2, faces, duplicate faces and half-edges grouped by undirected edge.
//
//  2. Boundary-oriented half-edges per face ring (holes turned against the outer ring), grouped by
//     undirected welded edge. Faces written twice are resolved (same way: one kept; opposite ways:
//     a wall between two closed parts, both dropped). Edges seen by one facet only are split where
//     another such edge's end lies on them (T-junctions, frequent in CityGML LoD2), then regrouped.
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

/// Remembers the face's welded outer ring (ring_buf); a face seen before with the same ring (any
/// start, either direction) and ring count is noted in `dups` for resolve_duplicates(), with
/// `fwd` telling whether it runs the way the first one does. The hash does not depend on start
/// or direction, so nothing is rotated unless two hashes meet.
void Decomposer::note_face(std::uint32_t f, std::uint32_t ring_count) {
  const std::uint32_t* r = ws_.ring_buf.data();
  const std::size_t k = ring_len_;
  std::uint64_t sum = 0, x = 0;
  for (std::size_t i = 0; i < k; ++i) {
    const std::uint64_t m = (r[i] + 1) * 0x9E3779B97F4A7C15ULL;
    sum += m ^ (m >> 29);
    x ^= m;
  }
  const std::uint64_t h = mix64(sum ^ (x << 1) ^ (k * 0xC2B2AE3D27D4EB4FULL + ring_count));
  auto& T = ws_.face_table;
  for (std::size_t s = h & T.mask;; s = (s + 1) & T.mask) {
    FaceEntry& e = T.slots[s];
    if (e.gen != T.gen) {
      e = FaceEntry{h, f, static_cast<std::uint32_t>(ws_.canon.size()), static_cast<std::uint32_t>(k), ring_count, T.gen};
      ws_.canon.insert(ws_.canon.end(), r, r + k);
      return;
    }
    if (e.hash != h || e.count != k || e.rings != ring_count) continue;
    const int dir = same_cycle(ws_.canon.data() + e.first, r, k);
    if (dir == 0) continue;
    if (ws_.dups.empty() || ws_.dups.back().slot != s || ws_.dups.back().face != e.face)
      ws_.dups.push_back(Dup{static_cast<std::uint32_t>(s), e.face, true});
    ws_.dups.push_back(Dup{static_cast<std::uint32_t>(s), f, dir > 0});
    return;
  }
}

/// +1 when ring b is ring a from another start, -1 when it is a reversed, 0 otherwise (k >= 3).
int Decomposer::same_cycle(const std::uint32_t* a, const std::uint32_t* b, std::size_t k) {
  std::size_t j = 0;
  while (j < k && a[j] != b[0]) ++j;
  if (j == k) return 0;
  bool fwd = true, bwd = true;
  for (std::size_t i = 1; i < k && (fwd || bwd); ++i) {
    fwd = fwd && b[i] == a[(j + i) % k];
    bwd = bwd && b[i] == a[(j + k - i) % k];
  }
  return fwd ? 1 : bwd ? -1 : 0;
}

/// Faces written more than once. Copies running opposite ways are a face between two solids of one
/// mesh (each part closed on its own): both go, and the parts merge into one solid. Copies running
/// the same way are one face written twice (exporters do it): one stays. Either would otherwise
/// make the edges non-manifold and cancel the part's volume.
void Decomposer::resolve_duplicates() {
  if (ws_.dups.empty()) return;
  auto& d = ws_.dups;
  std::sort(d.begin(), d.end(), [](const Dup& x, const Dup& y) { return x.slot < y.slot || (x.slot == y.slot && x.face < y.face); });
  d.erase(std::unique(d.begin(), d.end(), [](const Dup& x, const Dup& y) { return x.slot == y.slot && x.face == y.face; }),
          d.end());
  for (std::size_t i = 0; i < d.size();) {
    std::size_t j = i;
    std::size_t nf = 0, nb = 0;
    while (j < d.size() && d[j].slot == d[i].slot) (d[j].fwd ? nf : nb) += 1, ++j;
    std::size_t cancel = std::min(nf, nb), keep = nf + nb > 2 * cancel ? 1 : 0;
    std::size_t cf = cancel, cb = cancel;
    for (std::size_t k = i; k < j; ++k) {
      std::size_t& c = d[k].fwd ? cf : cb;
      if (c > 0) {
        --c;
      } else if (keep > 0) {
        --keep;
        continue;
      }
      ws_.faces[d[k].face].cls = kSkipped;
      ++stats_->duplicate_faces;
      --stats_->faces_used;
    }
    i = j;
  }
  auto& he = ws_.halfedges;
  he.erase(std::remove_if(he.begin(), he.end(), [&](const HalfEdge& h) { return ws_.faces[h.face].cls == kSkipped; }),
           he.end());
}

void Decomposer::build_faces() {
  tol_ = std::max(p_.weld_tolerance_m, 1e-9);
  tol2_ = tol_ * tol_;
  inv_cell_ = 1.0 / (kCell * tol_);
  const double cos_tol = std::cos(std::clamp(p_.proxy_tolerance_deg, 0.0, 89.0) * kPi / 180.0);
  cos2_tol_ = cos_tol * cos_tol;
  ws_.wpos.clear();
  grid_ = !distinct_apart();
  ws_.wpos.reserve(ws_.distinct_pos.size());
  if (grid_) {
    ws_.weld.assign(m_.vertices.size(), kNone);
    const std::size_t distinct = std::min(m_.indices.size(), m_.vertices.size());
    ws_.weld_table.start(distinct);
    ws_.exact_table.start(distinct);
  }
  if (ws_.ring_buf.size() < m_.indices.size()) ws_.ring_buf.resize(m_.indices.size());
  ws_.faces.assign(m_.faces.size(), FaceInfo{});
  ws_.face_table.start(m_.faces.size());
  ws_.canon.clear();
  ws_.dups.clear();
  ws_.halfedges.clear();
  ws_.halfedges.reserve(m_.indices.size());
  if (grid_) build_face_rings<true>();
  else build_face_rings<false>();
  stats_->vertices_welded = ws_.wpos.size();
}

/// See decomposer.h (one pass per ring).
template <bool Grid>
void Decomposer::build_face_rings() {
  const std::size_t nrings = m_.ring_count();
  const MeshFace* MF = m_.faces.data();
  FaceInfo* FI = ws_.faces.data();
  const std::uint32_t nf = static_cast<std::uint32_t>(m_.faces.size());
  const std::uint32_t* idx = m_.indices.data();
  const std::uint32_t* ro = m_.ring_offsets.data();
  const std::size_t nv = m_.vertices.size();
  const std::size_t npos = ws_.distinct_pos.size();
  const std::uint32_t* of = ws_.distinct_of.data();
  std::uint32_t* dw = ws_.distinct_weld.data();
  const V3* dpos = ws_.distinct_pos.data();
  if (!Grid) ws_.wpos.resize(npos);  // grid: weld_new() appends (reserved for npos: data() stays)
  V3* W = ws_.wpos.data();
  std::uint32_t nw = 0;
  std::uint32_t* out = ws_.ring_buf.data();
  const std::size_t maxh = m_.indices.size();
  ws_.halfedges.resize(maxh);
  HalfEdge* HE = ws_.halfedges.data();
  std::uint32_t nh = 0, ng = 0;
  auto& headv = ws_.bucket_start;
  headv.assign(npos, kNone);
  std::uint32_t* head = headv.data();
  if (ws_.he_next.size() < maxh) ws_.he_next.resize(maxh), ws_.he_max.resize(maxh), ws_.he_group.resize(maxh);
  if (ws_.cnt_buf.size() < maxh) ws_.cnt_buf.resize(maxh);
  std::uint32_t* next = ws_.he_next.data();
  std::uint32_t* hmax = ws_.he_max.data();
  std::uint32_t* grp = ws_.he_group.data();
  std::uint32_t* cnt = ws_.cnt_buf.data();
  // Ring r's welded vertices into out (repeats removed), Newell normal, box.
  // Welded id of mesh vertex vi (kBad for an index out of range or a non-finite vertex); without
  // the grid: its distinct point's id, given in order of first use (nwl: ids given so far).
  auto weld = [&](std::uint32_t vi, std::uint32_t& nwl) -> std::uint32_t {
    if (vi >= nv) return kBad;
    if constexpr (Grid) {
      return weld_vertex(vi);
    } else {
      const std::uint32_t d = of[vi];
      if (d == kBad) return kBad;
      std::uint32_t w = dw[d];
      if (w == kNone) dw[d] = w = nwl, W[nwl++] = dpos[d];
      return w;
    }
  };
  // Accumulators are locals (written out at the end): stores through W, out and dw could alias the
  // caller's variables and would keep them in memory.
  auto ring = [&](std::uint32_t r, V3& n_out, V3& lo_out, V3& hi_out, std::size_t& len_out) -> bool {
    std::size_t len = 0;
    std::uint32_t nwl = nw;
    V3 n{}, lo, hi;
    const std::uint32_t a = ro[r], b = ro[r + 1];
    bool ok = true;
    if (a < b) {
      V3 first, prev;
      {
        const std::uint32_t w = weld(idx[a], nwl);
        if (w == kBad) {
          len_out = 0;
          n_out = V3{};
          return false;
        }
        first = prev = lo = hi = W[w];
        out[len++] = w;
      }
      for (std::uint32_t k = a + 1; k < b; ++k) {
        const std::uint32_t w = weld(idx[k], nwl);
        if (w == kBad) {
          ok = false;
          break;
        }
        const V3 p = W[w];
        n.x += (prev.y - p.y) * (prev.z + p.z);
        n.y += (prev.z - p.z) * (prev.x + p.x);
        n.z += (prev.x - p.x) * (prev.y + p.y);
        lo.x = std::min(lo.x, p.x), lo.y = std::min(lo.y, p.y), lo.z = std::min(lo.z, p.z);
        hi.x = std::max(hi.x, p.x), hi.y = std::max(hi.y, p.y), hi.z = std::max(hi.z, p.z);
        prev = p;
        if (out[len - 1] != w) out[len++] = w;
      }
      if (ok) {
        n.x += (prev.y - first.y) * (prev.z + first.z);
        n.y += (prev.z - first.z) * (prev.x + first.x);
        n.z += (prev.x - first.x) * (prev.y + first.y);
        while (len > 1 && out[len - 1] == out[0]) --len;
      }
    }
    nw = nwl;
    len_out = len;
    n_out = n;
    lo_out = lo;
    hi_out = hi;
    return ok;
  };
  // The ring's half-edges (reversed for a hole running with the outer ring), each into its group.
  auto edges = [&](std::uint32_t f, std::size_t k, const V3 n, const double len2, bool wall, bool reverse) {
    std::uint32_t h = nh, g_n = ng;
    for (std::size_t i = 0; i < k; ++i) {
      std::uint32_t a = out[i], b = out[i + 1 < k ? i + 1 : 0];
      if (reverse) std::swap(a, b);
      HE[h] = HalfEdge{a, b, f, wall ? rise(W, n, len2, a, b) : std::int8_t{0}};
      group_half_edge(h, std::min(a, b), std::max(a, b), head, next, hmax, grp, cnt, g_n);
      ++h;
    }
    nh = h;
    ng = g_n;
  };
  V3 n, lo, hi, nh3, hlo, hhi;
  std::size_t len = 0;
  for (std::uint32_t f = 0; f < nf; ++f) {
    const MeshFace& mf = MF[f];
    FaceInfo& fi = FI[f];
    fi.uf = f;
    if (mf.kind == SurfaceKind::FootPrint || mf.kind == SurfaceKind::RoofEdge) continue;
    if (mf.ring_count == 0 || std::size_t(mf.first_ring) + mf.ring_count > nrings) continue;
    if (!ring(mf.first_ring, n, lo, hi, len) || len < 3) continue;
    const double len2 = dot(n, n);
    if (!(len2 > 1e-24)) continue;  // zero area: no orientation, no class
    ring_len_ = len;
    note_face(f, mf.ring_count);
    fi.n = n;
    fi.len = std::sqrt(len2);
    fi.net = n;
    fi.c = W[out[0]];
    fi.lo = lo;
    fi.hi = hi;
    const bool wall = n.z * n.z < cos2_tol_ * len2;
    fi.cls = wall ? kWall : kFloor;
    ++stats_->faces_used;
    edges(f, len, n, len2, wall, false);
    for (std::uint32_t r = mf.first_ring + 1; r < mf.first_ring + mf.ring_count; ++r) {
      if (!ring(r, nh3, hlo, hhi, len) || len < 3) continue;
      const bool same = dot(nh3, n) > 0;
      fi.net = same ? fi.net - nh3 : V3{fi.net.x + nh3.x, fi.net.y + nh3.y, fi.net.z + nh3.z};
      edges(f, len, n, len2, wall, same);
    }
  }
  ring_len_ = 0;
  if (!Grid) ws_.wpos.resize(nw);
  ws_.halfedges.resize(nh);
  ng_ = ng;
}

/// Groups from he_group and cnt_buf (ng groups): group_count, group_start, group_members.
void Decomposer::finish_groups(std::uint32_t ng) {
  const std::uint32_t* cnt = ws_.cnt_buf.data();
  ws_.group_count.assign(cnt, cnt + ng);
  sort_group_members(ng);
}

/// group_start and group_members (counting sort of the half-edges by he_group) from group_count.
void Decomposer::sort_group_members(std::uint32_t ng) {
  const std::size_t nh = ws_.halfedges.size();
  const std::uint32_t* cnt = ws_.group_count.data();
  auto& start = ws_.group_start;
  start.resize(ng + 1);
  std::uint32_t* st = start.data();
  st[0] = 0;
  for (std::size_t g = 0; g < ng; ++g) st[g + 1] = st[g] + cnt[g];
  auto& cursor = ws_.bucket_start;
  cursor.assign(start.begin(), start.end() - 1);
  std::uint32_t* cur = cursor.data();
  ws_.group_members.resize(nh);
  std::uint32_t* mem = ws_.group_members.data();
  const std::uint32_t* grp = ws_.he_group.data();
  for (std::uint32_t i = 0; i < nh; ++i) mem[cur[grp[i]]++] = i;
}

/// Half-edges grouped by undirected welded edge, groups numbered in order of first appearance:
/// the earlier half-edges with the same smaller vertex are chained per vertex (a handful), so a
/// half-edge finds its group by walking that chain. Then group_members in group order by a
/// counting sort.
void Decomposer::group_edges() {
  const std::size_t nh = ws_.halfedges.size(), nv = ws_.wpos.size();
  auto& head = ws_.bucket_start;  // per smaller vertex: latest half-edge with it, kNone if none
  head.assign(nv, kNone);
  ws_.he_next.resize(nh);
  ws_.he_max.resize(nh);
  ws_.he_group.resize(nh);
  std::uint32_t* H0 = head.data();
  std::uint32_t* next = ws_.he_next.data();
  std::uint32_t* hmax = ws_.he_max.data();
  std::uint32_t* grp = ws_.he_group.data();
  auto& count = ws_.group_count;
  count.resize(nh);  // at most one group per half-edge
  std::uint32_t* cnt = count.data();
  std::uint32_t ng = 0;
  const HalfEdge* H = ws_.halfedges.data();
  for (std::uint32_t i = 0; i < nh; ++i)
    group_half_edge(i, std::min(H[i].a, H[i].b), std::max(H[i].a, H[i].b), H0, next, hmax, grp, cnt, ng);
  count.resize(ng);
  sort_group_members(ng);
}

}  // namespace groundplan::footprint::detail

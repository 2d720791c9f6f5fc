// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 1, welding.
//
//  1. Weld vertices within weld_tolerance_m: readers give every polygon its own copy of its corners
//     (bit for bit the same: one hash of the raw coordinates finds them), and triangle soup has no
//     connectivity at all (the paper's stated limitation: coordinates not seen before go to a grid of
//     16 x tol cells, the neighbouring cells probed only within tol of a side). One pass per ring
//     welds, takes the Newell normal and bounding box, and tells walls from the rest (no square root:
//     which edges a wall rises from is decided on squares).
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

/// Distinct points of the mesh (bit for bit; non-finite ones kBad) into distinct_of / distinct_pos,
/// and whether no two of them lie within tol (then the grid is not needed). Readers give every
/// polygon its own copies of shared corners, bit for bit the same: one hash of the raw coordinates
/// finds those. Pairs are looked for in x order; those closer than 2 tol in x are measured as
/// probe() measures them (|dx| > 2 tol gives a squared distance above tol^2 even rounded). Comparing
/// bits finds what comparing values did in the grid: +0/-0 copies differ in bits but lie at
/// distance 0 (then the grid welds them), and non-finite points are kBad either way.
bool Decomposer::distinct_apart() {
  const std::size_t nv = m_.vertices.size();
  auto& X = ws_.exact_table;
  X.start(nv);
  auto& of = ws_.distinct_of;
  auto& pos = ws_.distinct_pos;
  of.resize(nv);
  pos.clear();
  static_assert(sizeof(Point3) == 24);
  const Point3* MV = m_.vertices.data();
  std::uint32_t* OF = of.data();
  ExactEntry* XS = X.slots.data();
  const std::size_t xmask = X.mask;
  const std::uint32_t xgen = X.gen;
  constexpr std::uint64_t kExp = 0x7ffULL << 52;  // all ones: infinite or NaN (std::isfinite false)
  for (std::uint32_t vi = 0; vi < nv; ++vi) {
    const Point3& q = MV[vi];
    std::uint64_t bx, by, bz;
    std::memcpy(&bx, &q.x, 8), std::memcpy(&by, &q.y, 8), std::memcpy(&bz, &q.z, 8);
    if ((bx & kExp) == kExp || (by & kExp) == kExp || (bz & kExp) == kExp) {
      OF[vi] = kBad;
      continue;
    }
    std::size_t es = bits_hash(bx, by, bz) & xmask;
    for (;; es = (es + 1) & xmask) {
      const ExactEntry& e = XS[es];
      if (e.gen != xgen) {
        const std::uint32_t d = static_cast<std::uint32_t>(pos.size());
        XS[es] = ExactEntry{vi, d, xgen};
        pos.push_back(V3{q.x - o_.x, q.y - o_.y, q.z - o_.z});
        OF[vi] = d;
        break;
      }
      std::uint64_t ex, ey, ez;  // bit for bit, as memcmp of the three doubles
      const Point3& r = MV[e.vertex];
      std::memcpy(&ex, &r.x, 8), std::memcpy(&ey, &r.y, 8), std::memcpy(&ez, &r.z, 8);
      if (ex == bx && ey == by && ez == bz) {
        OF[vi] = e.rep;
        break;
      }
    }
  }
  ws_.distinct_weld.assign(pos.size(), kNone);
  const std::size_t n = pos.size();
  if (n < 2) return true;
  auto& xs = ws_.weld_sort;
  xs.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) xs[i] = XId{pos[i].x, i};
  std::sort(xs.begin(), xs.end(), [](const XId& u, const XId& v) { return u.x < v.x; });
  const double w = 2 * tol_;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double lim = xs[i].x + w;
    for (std::size_t j = i + 1; j < n && xs[j].x <= lim; ++j) {
      const V3 d = pos[xs[j].id] - pos[xs[i].id];
      if (dot(d, d) <= tol2_) return false;
    }
  }
  return true;
}

/// The grid weld (vertices within tol of each other): exact copies through one hash of the raw
/// coordinates, points not seen before through the tolerance grid (weld_new). Grid cells are
/// kCell x tol wide, so a point needs the neighbouring cell on an axis only within tol of that
/// side (mostly one probe).
std::uint32_t Decomposer::weld_vertex_grid(std::uint32_t vi) {
  const Point3& q = m_.vertices[vi];
  std::uint64_t bx, by, bz;
  std::memcpy(&bx, &q.x, 8), std::memcpy(&by, &q.y, 8), std::memcpy(&bz, &q.z, 8);
  auto& X = ws_.exact_table;
  std::size_t es = bits_hash(bx, by, bz) & X.mask;
  for (;; es = (es + 1) & X.mask) {
    const ExactEntry& e = X.slots[es];
    if (e.gen != X.gen) break;
    if (std::memcmp(&m_.vertices[e.vertex], &q, sizeof(Point3)) == 0) return e.rep;
  }
  const std::uint32_t w = weld_new(q);
  X.slots[es] = ExactEntry{vi, w, X.gen};
  return w;
}

/// Welded id of a point not seen before (by its exact coordinates).
std::uint32_t Decomposer::weld_new(const Point3& q) {
  std::uint32_t w;
  if (!(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z))) return kBad;
  const V3 p{q.x - o_.x, q.y - o_.y, q.z - o_.z};
  const double tx = p.x * inv_cell_, ty = p.y * inv_cell_, tz = p.z * inv_cell_;
  const double fx = floor_fast(tx), fy = floor_fast(ty), fz = floor_fast(tz);
  // Cells beyond int32 range (a mesh kilometres across with a tiny tolerance) just clamp: the
  // exact distance test keeps welding correct, only the hashing gets slower.
  auto clampi = [](double v) { return static_cast<std::int32_t>(std::clamp(v, -2.0e9, 2.0e9)); };
  const std::int32_t kx = clampi(fx), ky = clampi(fy), kz = clampi(fz);
  std::uint32_t found = probe(kx, ky, kz, p);
  if (found != kNone) return found;
  auto side = [](double frac) { return frac < 1 / kCell ? -1 : frac > 1 - 1 / kCell ? 1 : 0; };
  const std::int32_t sx = side(tx - fx), sy = side(ty - fy), sz = side(tz - fz);
  if (const int near = (sx != 0) | (sy != 0) << 1 | (sz != 0) << 2) {
    for (int c = 1; c < 8; ++c) {
      if (c & ~near) continue;
      found = probe(kx + ((c & 1) ? sx : 0), ky + ((c & 2) ? sy : 0), kz + ((c & 4) ? sz : 0), p);
      if (found != kNone) return found;
    }
  }
  w = static_cast<std::uint32_t>(ws_.wpos.size());
  ws_.wpos.push_back(p);
  auto& T = ws_.weld_table;
  std::size_t h = cell_hash(kx, ky, kz) & T.mask;
  while (!T.empty(h)) h = (h + 1) & T.mask;
  T.slots[h] = WeldEntry{kx, ky, kz, w, T.gen};
  return w;
}

/// Welded vertices of ring r into ring_tmp, consecutive repeats (and the closing repeat) removed.
/// False when the ring has an index out of range or a non-finite vertex.
bool Decomposer::welded_ring(std::uint32_t r) {
  auto& out = ws_.ring_tmp;
  out.clear();
  const std::uint32_t a = m_.ring_offsets[r], b = m_.ring_offsets[r + 1];
  for (std::uint32_t k = a; k < b; ++k) {
    const std::uint32_t vi = m_.indices[k];
    if (vi >= m_.vertices.size()) return false;
    const std::uint32_t w = weld_vertex(vi);
    if (w == kBad) return false;
    if (out.empty() || out.back() != w) out.push_back(w);
  }
  while (out.size() > 1 && out.back() == out.front()) out.pop_back();
  return true;
}

}  // namespace groundplan::footprint::detail

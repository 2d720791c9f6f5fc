// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 2b, T-junctions: open edges split where another open edge ends on them.
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {
namespace {

/// Does p lie within sqrt(tol2) of the open edge A + t d (0 < t < 1, L2 = |d|^2)? t: its parameter.
inline bool inside_edge(const V3& p, const V3& A, const V3& d, double L2, double tol2, double& t) {
  const V3 ap = p - A;
  t = dot(ap, d) / L2;
  if (!(t > 0) || !(t < 1)) return false;
  const V3 off{ap.x - t * d.x, ap.y - t * d.y, ap.z - t * d.z};
  return dot(off, off) <= tol2;
}

}  // namespace

/// Splits every edge seen by one facet at the ends of other such edges lying on it (within tol).
/// Returns whether anything was split (then the edges must be regrouped).
bool Decomposer::split_t_junctions() {
  // Nearly every mesh has none: a look with the split's own test first (open_end_on_open_edge),
  // and only where an end lies on an edge the split as it always was.
  if (!open_end_on_open_edge()) return false;
  auto& ends = ws_.xends;
  ends.clear();
  const std::size_t ng = ws_.group_count.size();
  const auto& P = ws_.wpos;
  for (std::size_t g = 0; g < ng; ++g) {
    if (ws_.group_count[g] != 1) continue;
    const HalfEdge& h = ws_.halfedges[ws_.group_members[ws_.group_start[g]]];
    ends.push_back(XEnd{P[h.a].x, P[h.a].y, P[h.a].z, h.a});
    ends.push_back(XEnd{P[h.b].x, P[h.b].y, P[h.b].z, h.b});
  }
  std::sort(ends.begin(), ends.end(), [](const XEnd& u, const XEnd& v) { return u.x < v.x || (u.x == v.x && u.v < v.v); });
  ends.erase(std::unique(ends.begin(), ends.end(), [](const XEnd& u, const XEnd& v) { return u.v == v.v; }), ends.end());

  // Most meshes have none: look first (boxes of the edges against the sorted ends), split after.
  auto lies_on_some_edge = [&](const HalfEdge& h) {
    const V3 &A = P[h.a], &B = P[h.b];
    const double xlo = std::min(A.x, B.x) - tol_, xhi = std::max(A.x, B.x) + tol_;
    const double ylo = std::min(A.y, B.y) - tol_, yhi = std::max(A.y, B.y) + tol_;
    const double zlo = std::min(A.z, B.z) - tol_, zhi = std::max(A.z, B.z) + tol_;
    auto it = std::lower_bound(ends.begin(), ends.end(), xlo, [](const XEnd& u, double x) { return u.x < x; });
    for (; it != ends.end() && it->x <= xhi; ++it)
      if (it->y >= ylo && it->y <= yhi && it->z >= zlo && it->z <= zhi && it->v != h.a && it->v != h.b) return true;
    return false;
  };
  bool candidate = false;
  for (std::size_t g = 0; g < ng && !candidate; ++g)
    candidate = ws_.group_count[g] == 1 && lies_on_some_edge(ws_.halfedges[ws_.group_members[ws_.group_start[g]]]);
  if (!candidate) return false;
  auto& out = ws_.split_tmp;
  out.clear();
  bool any = false;
  struct Hit {
    double t;
    std::uint32_t v;
  };
  Hit hits[64];
  const double tol2 = tol_ * tol_;
  for (std::size_t i = 0; i < ws_.halfedges.size(); ++i) {
    const HalfEdge h = ws_.halfedges[i];
    if (ws_.group_count[ws_.he_group[i]] != 1) {
      out.push_back(h);
      continue;
    }
    const V3 &A = P[h.a], &B = P[h.b];
    const V3 d = B - A;
    const double L2 = dot(d, d);
    int nhits = 0;
    const double xlo = std::min(A.x, B.x) - tol_, xhi = std::max(A.x, B.x) + tol_;
    auto it = std::lower_bound(ends.begin(), ends.end(), xlo, [](const XEnd& u, double x) { return u.x < x; });
    for (; it != ends.end() && it->x <= xhi && nhits < 64; ++it) {
      const std::uint32_t v = it->v;
      if (v == h.a || v == h.b) continue;
      double t = 0;
      if (!inside_edge(P[v], A, d, L2, tol2, t)) continue;
      hits[nhits++] = Hit{t, v};
    }
    if (nhits == 0) {
      out.push_back(h);
      continue;
    }
    any = true;
    stats_->t_junction_splits += nhits;
    std::sort(hits, hits + nhits, [](const Hit& x, const Hit& y) { return x.t < y.t || (x.t == y.t && x.v < y.v); });
    const FaceInfo& fi = ws_.faces[h.face];
    std::uint32_t prev = h.a;
    for (int k = 0; k <= nhits; ++k) {
      const std::uint32_t next = k < nhits ? hits[k].v : h.b;
      if (next == prev) continue;
      out.push_back(HalfEdge{prev, next, h.face, fi.cls == kWall ? rise(P.data(), fi.n, fi.len * fi.len, prev, next) : std::int8_t{0}});
      prev = next;
    }
  }
  if (any) ws_.halfedges.swap(out);
  return any;
}

/// Whether some end of an edge seen by one facet lies on another such edge by the split's test
/// (x within the edge's x range widened by tol, then 0 < t < 1 and squared offset within tol^2):
/// exactly when the split would split something. Fewer than two such edges: never. The ends (each
/// vertex once) are tried against every edge when there are few (a closed part without its ground
/// has its bottom ring), else in x order from a binary search.
bool Decomposer::open_end_on_open_edge() {
  const std::size_t ng = ws_.group_count.size();
  const V3* P = ws_.wpos.data();
  auto& edges = ws_.open_he;
  edges.clear();
  auto& ends = ws_.weld_sort;  // (x, vertex), each vertex once
  ends.clear();
  auto& seen = ws_.end_seen;
  if (seen.size() < ws_.wpos.size()) seen.resize(ws_.wpos.size(), 0);
  if (++ws_.end_gen == 0) {
    std::fill(seen.begin(), seen.end(), 0);
    ws_.end_gen = 1;
  }
  const std::uint32_t gen = ws_.end_gen;
  const std::uint32_t* cnt = ws_.group_count.data();
  const std::uint32_t* st = ws_.group_start.data();
  const std::uint32_t* mem = ws_.group_members.data();
  const HalfEdge* H = ws_.halfedges.data();
  for (std::size_t g = 0; g < ng; ++g) {
    if (cnt[g] != 1) continue;
    const HalfEdge& h = H[mem[st[g]]];
    edges.push_back(mem[st[g]]);
    if (seen[h.a] != gen) seen[h.a] = gen, ends.push_back(XId{P[h.a].x, h.a});
    if (seen[h.b] != gen) seen[h.b] = gen, ends.push_back(XId{P[h.b].x, h.b});
  }
  const std::size_t ne = edges.size(), nx = ends.size();
  if (ne < 2) return false;
  const double tol2 = tol_ * tol_;
  const XId* E = ends.data();
  const bool sorted = ne * nx > 1024;
  if (sorted) std::sort(ends.begin(), ends.end(), [](const XId& u, const XId& v) { return u.x < v.x; });
  for (std::size_t i = 0; i < ne; ++i) {
    const HalfEdge& h = H[edges[i]];
    const V3 &A = P[h.a], &B = P[h.b];
    const V3 d = B - A;
    const double L2 = dot(d, d);
    const double xlo = std::min(A.x, B.x) - tol_, xhi = std::max(A.x, B.x) + tol_;
    std::size_t j = 0, stop = nx;
    if (sorted) j = std::lower_bound(E, E + nx, xlo, [](const XId& u, double x) { return u.x < x; }) - E;
    for (; j < stop; ++j) {
      const double x = E[j].x;
      if (!(x <= xhi)) {
        if (sorted) break;
        continue;
      }
      if (!(x >= xlo)) continue;
      const std::uint32_t v = E[j].id;
      if (v == h.a || v == h.b) continue;
      double t = 0;
      if (!inside_edge(P[v], A, d, L2, tol2, t)) continue;
      return true;
    }
  }
  return false;
}

}  // namespace groundplan::footprint::detail

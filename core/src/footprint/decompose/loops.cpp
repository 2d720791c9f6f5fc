// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 6, loop chaining.
//
//  6. Footprint edges, directed by the outward facet (building on the left), are chained into loops
//     over welded vertices; at a vertex with several ways on, the leftmost turn is taken (ties by
//     edge order), which keeps rings simple where parts touch at a corner. Chains that do not close
//     are not local-minimum loops (the edge of a soffit, a part standing on another) and are dropped.
//     Chains still open are chained again in plan view (endpoints within the weld tolerance in x, y
//     are one vertex): a bottom stepping at a vertical edge is continuous in plan (terraced sites).
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

void Decomposer::chain_loops() {
  chain_pass(true);
  if (stats_->open_chains == 0) return;
  auto& cand = ws_.cand;
  lower_boundary_len_ = 0;
  for (const DirEdge& e : cand) lower_boundary_len_ += plan_length(e);
  // Rule 2: the edges left open are chained again in plan view. A bottom that steps at a vertical
  // wall edge (terraced sites, a wall on a plinth on one side only) is broken in 3D but continuous
  // in plan, and the footprint is a plan-view object. Loops already closed stay as they are.
  auto& open = ws_.open_tmp;
  open.clear();
  for (std::uint32_t e : ws_.open_edges) open.push_back(cand[e]);
  if (!merge_in_plan(open)) return;
  const std::size_t loops_before = ws_.loops.size();
  // cand takes the merged open edges; every lower-boundary edge waits in lower_edges for
  // close_in_plan() (collecting them again there cost as much as the first time).
  ws_.lower_edges.swap(cand);
  cand.swap(open);
  lower_moved_ = true;
  stats_->open_chains = 0;
  chain_pass(false);
  stats_->chained_in_plan = ws_.loops.size() - loops_before;
}

/// Footprint-edge endpoints within the weld tolerance in x, y become one vertex (the one of
/// smallest id); edges that collapse go. False when nothing was merged.
bool Decomposer::merge_in_plan(std::vector<DirEdge>& cand) {
  auto& ends = ws_.endpoints;
  ends.clear();
  for (const DirEdge& e : cand) ends.push_back(e.from), ends.push_back(e.to);
  const auto& P = ws_.wpos;
  std::sort(ends.begin(), ends.end(), [&](std::uint32_t u, std::uint32_t v) { return P[u].x < P[v].x || (P[u].x == P[v].x && u < v); });
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  auto& rep = ws_.plan_rep;
  rep.resize(P.size());
  for (std::uint32_t v : ends) rep[v] = v;
  auto find = [&](std::uint32_t x) {
    while (rep[x] != x) x = rep[x] = rep[rep[x]];
    return x;
  };
  bool any = false;
  for (std::size_t i = 0; i < ends.size(); ++i)
    for (std::size_t j = i + 1; j < ends.size() && P[ends[j]].x - P[ends[i]].x <= tol_; ++j) {
      if (std::fabs(P[ends[j]].y - P[ends[i]].y) > tol_) continue;
      const std::uint32_t a = find(ends[i]), b = find(ends[j]);
      if (a == b) continue;
      rep[std::max(a, b)] = std::min(a, b);
      any = true;
    }
  if (!any) return false;
  std::size_t k = 0;
  for (const DirEdge& e : cand) {
    const DirEdge m{find(e.from), find(e.to), e.comp};
    if (m.from != m.to) cand[k++] = m;
  }
  cand.resize(k);
  return true;
}

/// Chains ws_.cand into loops (appended to ws_.loops; cleared first when `fresh`); the edges of
/// chains that do not close go to ws_.open_edges.
void Decomposer::chain_pass(bool fresh) {
  auto& cand = ws_.cand;
  if (fresh) {
    ws_.loops.clear();
    ws_.loop_pts.clear();
  }
  ws_.open_edges.clear();
  if (cand.empty()) return;
  const std::size_t nv = ws_.wpos.size(), ne = cand.size();
  ws_.out_start.assign(nv + 1, 0);
  for (const DirEdge& e : cand) ++ws_.out_start[e.from + 1];
  for (std::size_t v = 0; v < nv; ++v) ws_.out_start[v + 1] += ws_.out_start[v];
  ws_.out_list.resize(ne);
  {
    auto& cursor = ws_.stamp;  // borrowed as a cursor
    cursor.assign(ws_.out_start.begin(), ws_.out_start.end() - 1);
    for (std::uint32_t i = 0; i < ne; ++i) ws_.out_list[cursor[cand[i].from]++] = i;
  }
  ws_.used.assign(ne, 0);
  ws_.stamp.assign(nv, 0);  // position in the current chain + 1, 0 = not in it
  auto& cv = ws_.chain_v;
  auto& ce = ws_.chain_e;
  for (std::uint32_t e0 = 0; e0 < ne; ++e0) {
    if (ws_.used[e0]) continue;
    cv.clear();
    ce.clear();
    cv.push_back(cand[e0].from);
    ws_.stamp[cand[e0].from] = 1;
    std::uint32_t e = e0;
    for (;;) {
      ws_.used[e] = 1;
      ce.push_back(e);
      const std::uint32_t v = cand[e].to;
      if (ws_.stamp[v] != 0) {
        // Back at a vertex of this chain: the part from there is a closed loop.
        const std::size_t k = ws_.stamp[v] - 1;
        emit_loop(k);
        for (std::size_t j = k + 1; j < cv.size(); ++j) ws_.stamp[cv[j]] = 0;
        cv.resize(k + 1);
        ce.resize(k);
      } else {
        cv.push_back(v);
        ws_.stamp[v] = static_cast<std::uint32_t>(cv.size());
      }
      const std::uint32_t next = pick_next(cv.back(), ce.empty() ? kNone : ce.back());
      if (next == kNone) break;
      e = next;
    }
    if (!ce.empty()) {
      ++stats_->open_chains;
      ws_.open_edges.insert(ws_.open_edges.end(), ce.begin(), ce.end());
    }
    for (std::uint32_t v : cv) ws_.stamp[v] = 0;
  }
}

/// The unused edge out of v making the leftmost turn after edge `in` (any unused one if none).
std::uint32_t Decomposer::pick_next(std::uint32_t v, std::uint32_t in) {
  std::uint32_t best = kNone;
  double best_ang = 10;
  const std::uint32_t s = ws_.out_start[v], t = ws_.out_start[v + 1];
  std::uint32_t avail = 0;
  for (std::uint32_t i = s; i < t; ++i) avail += !ws_.used[ws_.out_list[i]];
  if (avail == 0) return kNone;
  double back = 0;
  if (in != kNone && avail > 1) {
    const V3 d = ws_.wpos[ws_.cand[in].from] - ws_.wpos[v];
    back = std::atan2(d.y, d.x);
  }
  for (std::uint32_t i = s; i < t; ++i) {
    const std::uint32_t e = ws_.out_list[i];
    if (ws_.used[e]) continue;
    if (avail == 1 || in == kNone) return e;
    const V3 d = ws_.wpos[ws_.cand[e].to] - ws_.wpos[v];
    // Clockwise angle from the way back to this way, in (0, 2 pi]: the smallest is the leftmost turn.
    double a = back - std::atan2(d.y, d.x);
    while (a <= 1e-12) a += 2 * kPi;
    while (a > 2 * kPi) a -= 2 * kPi;
    if (a < best_ang) {
      best_ang = a;
      best = e;
    }
  }
  return best;
}

/// Loop = chain vertices from position k to the end (the last edge returns to cv[k]).
void Decomposer::emit_loop(std::size_t k) {
  const auto& cv = ws_.chain_v;
  Workspace::Loop L;
  L.comp = ws_.cand[ws_.chain_e[k]].comp;
  L.first = ws_.loop_pts.size();
  L.zmax = -std::numeric_limits<double>::infinity();
  for (std::size_t j = k; j < cv.size(); ++j) {
    const V3& p = ws_.wpos[cv[j]];
    L.zmax = std::max(L.zmax, p.z);
    const Point2 q{p.x, p.y};
    if (ws_.loop_pts.size() > L.first) {
      const Point2& b = ws_.loop_pts.back();
      if (b.x == q.x && b.y == q.y) continue;
    }
    ws_.loop_pts.push_back(q);
  }
  while (ws_.loop_pts.size() - L.first > 1 && ws_.loop_pts.back() == ws_.loop_pts[L.first]) ws_.loop_pts.pop_back();
  L.count = ws_.loop_pts.size() - L.first;
  double a = 0;
  L.minx = L.miny = std::numeric_limits<double>::infinity();
  L.maxx = L.maxy = -L.minx;
  const Point2* r = ws_.loop_pts.data() + L.first;
  for (std::size_t i = 0; i < L.count; ++i) {
    const Point2 &p = r[i], &q = r[i + 1 < L.count ? i + 1 : 0];
    a += p.x * q.y - q.x * p.y;
    L.minx = std::min(L.minx, p.x), L.maxx = std::max(L.maxx, p.x);
    L.miny = std::min(L.miny, p.y), L.maxy = std::max(L.maxy, p.y);
  }
  L.area = a / 2;
  ++stats_->loops;
  if (L.count < 3 || !(std::fabs(L.area) >= p_.min_loop_area_m2)) {
    ++stats_->dropped_loops;
    ws_.loop_pts.resize(L.first);
    return;
  }
  ws_.loops.push_back(L);
}

}  // namespace groundplan::footprint::detail

// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 7c, the lower boundary closed in plan
// (issue 21): tried before the shadow.
//
// SketchUp / Google Earth models are parts laid side by side that neither share edges nor meet exactly:
// Macky (kml-collada-macky-google) is a hall and a front block whose lower boundaries end 7 to 8 cm
// apart in plan and at different heights (the site falls 3.2 m to the back), some of its parts turned
// inside out (their open meshes give no volume to orient them by). The walls' lower boundary then
// closes no loop in 3D nor in plan at the weld tolerance, though in plan it is plainly the outline of
// the building. Here every lower-boundary edge is taken in plan, ends within kPlanGap_m of each other
// become one point (where two edges meet there, the crossing of their lines: the corner the walls
// meant), dangling chains are pruned (battlements, the foot of a turret on a roof: pieces that enclose
// nothing), and the bounded faces of the remaining plane graph are traced. A face is building when most
// of its boundary (plan length) runs with the building on the face's side, as the walls' outward
// orientation says, else open ground (a courtyard: a hole of the building face around it); a part
// turned inside out is outvoted. The building faces, united, are the footprint. Accepted only when at
// most a tenth of the lower boundary (plan length) was pruned outside the building faces (chains inside
// them are parts standing on others, as for the loops in polygons.cpp); the shadow stays the last resort.
// The faces are traced as in any planar map (at each vertex the next edge clockwise from the way back,
// so every bounded face runs counter-clockwise); edges crossing away from a vertex are not split, and
// the union engine sorts out the rings they make.
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace groundplan::footprint::detail {

bool Decomposer::close_in_plan(std::vector<Polygon>& out) {
  // Every lower-boundary edge: chain_loops() may have put the merged open ones in their place.
  if (lower_moved_) ws_.cand.swap(ws_.lower_edges), lower_moved_ = false;
  const std::vector<DirEdge>& cand = ws_.cand;
  if (cand.size() < 3) return false;
  const auto& P = ws_.wpos;
  double total = 0;
  for (const DirEdge& e : cand) total += plan_length(e);
  if (!(total > 0)) return false;
  stats_->lower_boundary_m = total;
  stats_->plan_gap_m = kPlanGap_m;

  // 1. Ends within kPlanGap_m in plan become one point.
  auto by_x = [&](std::uint32_t u, std::uint32_t v) { return P[u].x < P[v].x || (P[u].x == P[v].x && u < v); };
  std::vector<std::uint32_t> ends;
  ends.reserve(2 * cand.size());
  for (const DirEdge& e : cand) ends.push_back(e.from), ends.push_back(e.to);
  std::sort(ends.begin(), ends.end(), by_x);
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  const std::uint32_t ne = static_cast<std::uint32_t>(ends.size());
  std::vector<std::uint32_t> rep(ne);
  for (std::uint32_t i = 0; i < ne; ++i) rep[i] = i;
  auto find = [&](std::uint32_t x) {
    while (rep[x] != x) x = rep[x] = rep[rep[x]];
    return x;
  };
  const double g2 = kPlanGap_m * kPlanGap_m;
  for (std::uint32_t i = 0; i < ne; ++i)
    for (std::uint32_t j = i + 1; j < ne && P[ends[j]].x - P[ends[i]].x <= kPlanGap_m; ++j) {
      const double dx = P[ends[j]].x - P[ends[i]].x, dy = P[ends[j]].y - P[ends[i]].y;
      if (dx * dx + dy * dy > g2) continue;
      const std::uint32_t a = find(i), b = find(j);
      if (a != b) rep[std::max(a, b)] = std::min(a, b);
    }
  auto node = [&](std::uint32_t v) {
    return find(static_cast<std::uint32_t>(std::lower_bound(ends.begin(), ends.end(), v, by_x) - ends.begin()));
  };
  // Each point's place: one end, that end; two ends of edges that are not parallel, the crossing of
  // their lines when it lies within 2 kPlanGap_m of both; else the ends' mean.
  struct Acc {
    double x = 0, y = 0;
    std::uint32_t n = 0, near[2] = {0, 0}, far[2] = {0, 0};
  };
  std::vector<Acc> acc(ne);
  auto note_end = [&](std::uint32_t v, std::uint32_t other) {
    Acc& a = acc[node(v)];
    if (a.n < 2) a.near[a.n] = v, a.far[a.n] = other;
    a.x += P[v].x, a.y += P[v].y, ++a.n;
  };
  for (const DirEdge& e : cand) note_end(e.from, e.to), note_end(e.to, e.from);
  std::vector<Point2> at(ne);
  for (std::uint32_t c = 0; c < ne; ++c) {
    const Acc& a = acc[c];
    if (a.n == 0) continue;
    at[c] = Point2{a.x / a.n, a.y / a.n};
    if (a.n != 2 || a.near[0] == a.near[1]) continue;
    const V3 &p1 = P[a.near[0]], &q1 = P[a.far[0]], &p2 = P[a.near[1]], &q2 = P[a.far[1]];
    const double d1x = p1.x - q1.x, d1y = p1.y - q1.y, d2x = p2.x - q2.x, d2y = p2.y - q2.y;
    const double den = d1x * d2y - d1y * d2x;
    if (!(std::fabs(den) > 0.1 * std::hypot(d1x, d1y) * std::hypot(d2x, d2y))) continue;  // within ~6 degrees
    const double t = ((p2.x - q1.x) * d2y - (p2.y - q1.y) * d2x) / den;
    const Point2 x{q1.x + t * d1x, q1.y + t * d1y};
    if (std::hypot(x.x - p1.x, x.y - p1.y) <= 2 * kPlanGap_m && std::hypot(x.x - p2.x, x.y - p2.y) <= 2 * kPlanGap_m) at[c] = x;
  }

  // 2. Undirected plan edges between the points, each once (edges that collapse go), with the plan
  //    length of the lower boundary running from the smaller point to the larger (building on its
  //    left) less that running the other way.
  struct Edge {
    std::uint32_t a, b;
    double vote;
  };
  std::vector<Edge> all;
  all.reserve(cand.size());
  for (const DirEdge& e : cand) {
    const std::uint32_t a = node(e.from), b = node(e.to);
    if (a != b) all.push_back({std::min(a, b), std::max(a, b), a < b ? plan_length(e) : -plan_length(e)});
  }
  std::sort(all.begin(), all.end(), [](const Edge& u, const Edge& v) { return u.a < v.a || (u.a == v.a && u.b < v.b); });
  std::vector<Edge> edges;
  for (const Edge& e : all) {
    if (!edges.empty() && edges.back().a == e.a && edges.back().b == e.b) edges.back().vote += e.vote;
    else edges.push_back(e);
  }
  auto length = [&](std::size_t k) { return std::hypot(at[edges[k].b].x - at[edges[k].a].x, at[edges[k].b].y - at[edges[k].a].y); };

  // 3. Dangling chains pruned: a point with one edge encloses nothing.
  std::vector<std::uint32_t> degree(ne, 0);
  for (const Edge& e : edges) ++degree[e.a], ++degree[e.b];
  std::vector<std::uint8_t> gone(edges.size(), 0);
  for (bool again = true; again;) {
    again = false;
    for (std::size_t k = 0; k < edges.size(); ++k)
      if (!gone[k] && (degree[edges[k].a] < 2 || degree[edges[k].b] < 2)) {
        gone[k] = 1, again = true;
        --degree[edges[k].a], --degree[edges[k].b];
      }
  }
  double kept = 0;
  for (std::size_t k = 0; k < edges.size(); ++k)
    if (!gone[k]) kept += length(k);
  stats_->plan_kept_m = kept;

  // 4. Half-edges around each point by angle; faces traced with the face on the left, so bounded
  //    faces run counter-clockwise and each component's outside clockwise.
  struct Half {
    std::uint32_t from, to, edge;
    double angle;
  };
  std::vector<Half> half;
  for (std::uint32_t k = 0; k < edges.size(); ++k) {
    if (gone[k]) continue;
    const Point2 pa = at[edges[k].a], pb = at[edges[k].b];
    half.push_back({edges[k].a, edges[k].b, k, std::atan2(pb.y - pa.y, pb.x - pa.x)});
    half.push_back({edges[k].b, edges[k].a, k, std::atan2(pa.y - pb.y, pa.x - pb.x)});
  }
  std::sort(half.begin(), half.end(), [](const Half& u, const Half& v) { return u.from < v.from || (u.from == v.from && u.angle < v.angle); });
  std::vector<std::uint32_t> first(ne + 1, 0);
  for (const Half& h : half) ++first[h.from + 1];
  for (std::uint32_t n = 0; n < ne; ++n) first[n + 1] += first[n];
  auto index_of = [&](std::uint32_t from, std::uint32_t to) {
    for (std::uint32_t i = first[from]; i < first[from + 1]; ++i)
      if (half[i].to == to) return i;
    return kNone;
  };
  std::vector<std::uint8_t> used(half.size(), 0);
  std::vector<Polygon> building, ground;
  for (std::uint32_t h0 = 0; h0 < half.size(); ++h0) {
    if (used[h0]) continue;
    Ring ring;
    double vote = 0;
    for (std::uint32_t h = h0; h != kNone && !used[h];) {
      used[h] = 1;
      ring.push_back(at[half[h].from]);
      vote += half[h].from < half[h].to ? edges[half[h].edge].vote : -edges[half[h].edge].vote;
      // At the far end: the next edge clockwise from the way back.
      const std::uint32_t v = half[h].to, back = index_of(v, half[h].from);
      h = back == kNone ? kNone : back == first[v] ? first[v + 1] - 1 : back - 1;
    }
    if (ring.size() < 3 || !(ring_area(ring) >= p_.min_loop_area_m2)) continue;  // a component's outside
    (vote > 0 ? building : ground).push_back(Polygon{std::move(ring), {}});
  }
  if (building.empty()) return false;

  // 5. Pruned chains inside the building faces (a part standing on another) are no loss; outside,
  //    they are lower boundary that encloses nothing: over a tenth of it, and the faces miss the building.
  auto in_building = [&](Point2 q) {
    for (const Polygon& f : building)
      if (inside(f.outer.data(), f.outer.size(), q)) return true;
    return false;
  };
  double outside = 0;
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const Point2 a = at[edges[k].a], b = at[edges[k].b];
    if (gone[k] && !in_building(Point2{(a.x + b.x) / 2, (a.y + b.y) / 2})) outside += length(k);
  }
  stats_->plan_pruned_outside_m = outside;
  if (outside > 0.1 * total) return false;

  // 6. Open ground inside a building face (not beside it) is a hole of the smallest one around it:
  //    probed just inside the ground face, off the middle of its longest edge.
  for (Polygon& g : ground) {
    const Ring& r = g.outer;
    std::size_t best = 0;
    double bl = -1;
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Point2 &p = r[i], &q = r[(i + 1) % r.size()];
      const double l = std::hypot(q.x - p.x, q.y - p.y);
      if (l > bl) bl = l, best = i;
    }
    const Point2 &p = r[best], &q = r[(best + 1) % r.size()];
    const Point2 probe{(p.x + q.x) / 2 - (q.y - p.y) * 1e-3, (p.y + q.y) / 2 + (q.x - p.x) * 1e-3};  // left: inside
    Polygon* host = nullptr;
    double host_area = std::numeric_limits<double>::infinity();
    for (Polygon& f : building) {
      const double a = ring_area(f.outer);
      if (a < host_area && inside(f.outer.data(), f.outer.size(), probe)) host = &f, host_area = a;
    }
    if (host) host->holes.emplace_back(r.rbegin(), r.rend());
  }
  for (Polygon& f : building) {
    for (Point2& q : f.outer) q = Point2{q.x + o_.x, q.y + o_.y};
    for (Ring& h : f.holes)
      for (Point2& q : h) q = Point2{q.x + o_.x, q.y + o_.y};
  }
  // The union engine unites the faces and sorts out rings that touch or cross themselves.
  if (!unite_polygons(building, p_.min_loop_area_m2) || building.empty()) return false;
  out = std::move(building);
  stats_->closed_in_plan = true;
  return true;
}

}  // namespace groundplan::footprint::detail

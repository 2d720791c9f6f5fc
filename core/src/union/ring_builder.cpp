// SPDX-License-Identifier: MIT
// Ring builder (see ring_builder.h). Moved out of block_union.cpp.
#include "union/ring_builder.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <unordered_map>
#include <utility>

#include "robust/predicates.h"
#include "union/output_rounding.h"
#include "union/snap_round.h"

namespace groundplan::detail {

using robust::orient;

/// Splits a closed walk at repeated vertices into simple rings, drops spikes a-b-a and straight
/// vertices. Exact on the doubles: a ring of input vertices is part of the exact union whatever its
/// size (a 1e-9 m² gap between neighbours one ulp apart is a real hole of the input); snapped rings
/// have no collapsed parts left (snap_round cancels them).
void split_simple(const std::vector<Point2>& walk, std::vector<std::vector<Point2>>& out) {
  std::vector<Point2> pts;
  for (const Point2& p : walk)
    if (pts.empty() || !(pts.back() == p)) pts.push_back(p);
  while (pts.size() > 1 && pts.front() == pts.back()) pts.pop_back();
  struct H {
    std::size_t operator()(const Point2& p) const {
      std::uint64_t a, b;
      std::memcpy(&a, &p.x, 8);
      std::memcpy(&b, &p.y, 8);
      return std::hash<std::uint64_t>()(a * 0x9E3779B97F4A7C15ull ^ b);
    }
  };
  std::vector<Point2> stack;
  auto emit = [&](std::vector<Point2> r) {
    // remove spikes a-b-a left by rounding
    bool changed = true;
    while (changed && r.size() >= 3) {
      changed = false;
      for (std::size_t i = 0; i < r.size() && r.size() >= 3; ++i) {
        const std::size_t n = r.size();
        if (r[(i + n - 1) % n] == r[(i + 1) % n]) {
          const std::size_t hi = std::max(i, (i + 1) % n), lo = std::min(i, (i + 1) % n);
          r.erase(r.begin() + static_cast<std::ptrdiff_t>(hi));
          r.erase(r.begin() + static_cast<std::ptrdiff_t>(lo));
          changed = true;
          break;
        }
      }
    }
    // drop vertices where the ring goes straight on (exactly collinear, same direction)
    if (r.size() >= 3) {
      std::vector<Point2> k;
      k.reserve(r.size());
      const std::size_t n = r.size();
      for (std::size_t i = 0; i < n; ++i) {
        const Point2& a = r[(i + n - 1) % n];
        const Point2& b = r[i];
        const Point2& c = r[(i + 1) % n];
        if (orient(a, b, c) == 0 && same_way(a, b, b, c)) continue;
        k.push_back(b);
      }
      r.swap(k);
    }
    if (r.size() >= 3) out.push_back(std::move(r));
  };
  {
    // the common case: no vertex repeats, so the walk is one simple ring
    std::vector<Point2> sorted(pts);
    std::sort(sorted.begin(), sorted.end(),
              [](const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    if (std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end()) {
      emit(std::move(pts));
      return;
    }
  }
  std::unordered_map<Point2, std::size_t, H> pos;
  for (const Point2& p : pts) {
    auto it = pos.find(p);
    if (it != pos.end()) {
      const std::size_t k = it->second;
      std::vector<Point2> sub(stack.begin() + static_cast<std::ptrdiff_t>(k), stack.end());
      for (std::size_t i = k + 1; i < stack.size(); ++i) pos.erase(stack[i]);
      stack.resize(k + 1);
      emit(std::move(sub));
    } else {
      pos.emplace(p, stack.size());
      stack.push_back(p);
    }
  }
  emit(std::move(stack));
}

void assemble_block(const std::vector<RingOut>& rings_, const std::vector<Poly>& polys_,
                    const std::vector<Edge>& edges_, double pitch, BlockStats& stats_, BlockResult& out) {
  struct R {
    std::vector<Point2> pts;
    std::size_t src;  // index into parts_polys
    Box box;
    long double area2;
    bool snapped;
  };
  // Simple rings with the polygons bordering them. Walks that are all exact (every vertex an input
  // vertex) are the exact boundary: split at revisited vertices and kept bit for bit, unless they
  // near-touch. A group of nearby walks that is not clean is snap-rounded as a whole (snap_round.h).
  std::vector<std::vector<Point2>> parts;
  std::vector<std::vector<std::uint32_t>> parts_polys;
  std::vector<std::size_t> part_src;  // parts[k] has the polygons parts_polys[part_src[k]]
  std::vector<char> parts_snapped;    // parts[k] comes from snap rounding
  // Walks split as they are (crossings correctly rounded). Exact walks are the exact boundary. The
  // block is snap-rounded where that is not clean: a walk with a rounded crossing whose rings, as
  // rounded, are invalid, overlap or turned over, or output vertices closer than a pitch to another vertex
  // or edge, whether the union computed them or the input had them (issue 20: "vertices closer than δ
  // are one vertex"). Then the walks are grouped by proximity (groups more than 4 pitches apart are
  // independent) and each group that is not clean is snap-rounded; the others stay as split.
  bool any_rounded = false;
  for (const RingOut& r : rings_) any_rounded |= r.rounded;
  std::vector<std::size_t> first_part(rings_.size() + 1, 0);
  for (std::size_t i = 0; i < rings_.size(); ++i) {
    split_simple(rings_[i].pts, parts);
    first_part[i + 1] = parts.size();
  }
  std::vector<char> walk_snapped(rings_.size(), 0);
  std::vector<char> part_rounded;
  if (any_rounded) {
    part_rounded.assign(parts.size(), 0);
    for (std::size_t i = 0; i < rings_.size(); ++i)
      for (std::size_t k = first_part[i]; k < first_part[i + 1]; ++k) part_rounded[k] = rings_[i].rounded;
  }
  // A ring with a rounded crossing may have turned over (a sliver hole come out as an outer ring inside
  // another plan): its group is snap-rounded like an invalid one, even where it is far from every other walk.
  std::vector<char> part_flipped;
  bool any_flipped = false;
  if (any_rounded) {
    part_flipped = nesting_flips(parts, part_rounded);
    any_flipped = std::find(part_flipped.begin(), part_flipped.end(), 1) != part_flipped.end();
  }
  if (near_touching(parts, pitch) || (any_rounded && (any_flipped || !clean_near_rounded(parts, part_rounded, pitch)))) {
    const std::vector<std::uint32_t> group = proximity_groups(rings_, pitch);
    std::vector<char> has_flip(rings_.size(), 0);
    for (std::size_t i = 0; i < rings_.size() && any_flipped; ++i)
      for (std::size_t k = first_part[i]; k < first_part[i + 1]; ++k) has_flip[group[i]] |= part_flipped[k];
    std::vector<std::vector<std::uint32_t>> members(rings_.size());
    for (std::uint32_t i = 0; i < rings_.size(); ++i) members[group[i]].push_back(i);
    std::vector<std::vector<Point2>> snapped_parts;
    std::vector<std::vector<std::uint32_t>> snapped_polys;
    for (std::uint32_t gi = 0; gi < rings_.size(); ++gi) {
      if (members[gi].empty()) continue;
      std::vector<std::vector<Point2>> as_is;
      for (std::uint32_t i : members[gi])
        for (std::size_t k = first_part[i]; k < first_part[i + 1]; ++k) as_is.push_back(parts[k]);
      if (!has_flip[gi] && members[gi].size() < rings_.size() && clean_as_rounded(as_is, pitch, true)) continue;
      std::vector<RingOut> sub;
      for (std::uint32_t i : members[gi]) sub.push_back(rings_[i]);
      std::vector<SnappedRing> sr;
      SnapStats ss;
      if (!snap_round(sub, pitch, sr, ss)) {
        // cannot happen (docs/union_engine.md); rings that are valid as they are stay, only near-touching
        if (!has_flip[gi] && clean_as_rounded(as_is, pitch, false)) continue;
        out.problems.push_back(Problem{"", "", "union", "ROUNDING_INVALID",
                                       "snap rounding of a boundary did not give a consistent edge graph; "
                                       "its crossing points are rounded to nearest instead"});
        continue;
      }
      stats_.snapped_groups += 1;
      stats_.rounding_repairs += ss.cancelled;
      for (std::uint32_t i : members[gi]) {
        walk_snapped[i] = 1;
        for (std::uint32_t p : rings_[i].polys) out.snapped.push_back(polys_[p].footprint);
      }
      for (SnappedRing& r : sr) {
        snapped_parts.push_back(std::move(r.pts));
        snapped_polys.push_back(std::move(r.polys));
      }
    }
    std::vector<std::vector<Point2>> kept;
    for (std::size_t i = 0; i < rings_.size(); ++i) {
      if (walk_snapped[i]) continue;
      for (std::size_t k = first_part[i]; k < first_part[i + 1]; ++k) {
        kept.push_back(std::move(parts[k]));
        part_src.push_back(parts_polys.size());
        parts_snapped.push_back(0);
      }
      parts_polys.push_back(rings_[i].polys);
    }
    for (std::size_t k = 0; k < snapped_parts.size(); ++k) {
      kept.push_back(std::move(snapped_parts[k]));
      part_src.push_back(parts_polys.size());
      parts_snapped.push_back(1);
      parts_polys.push_back(std::move(snapped_polys[k]));
    }
    parts.swap(kept);
  } else {
    for (std::size_t i = 0; i < rings_.size(); ++i) {
      for (std::size_t k = first_part[i]; k < first_part[i + 1]; ++k) {
        part_src.push_back(parts_polys.size());
        parts_snapped.push_back(0);
      }
      parts_polys.push_back(rings_[i].polys);
    }
  }
  // Snap rounding turns no face over (docs/union_engine.md); checked exactly all the same on the snapped rings,
  // as the last resort: a turned ring would be a bug, reported.
  if (std::find(parts_snapped.begin(), parts_snapped.end(), 1) != parts_snapped.end()) {
    const std::vector<char> turned = nesting_flips(parts, parts_snapped);
    if (std::find(turned.begin(), turned.end(), 1) != turned.end())
      out.problems.push_back(Problem{"", "", "union", "ROUNDING_INVALID",
                                     "a snap-rounded ring lies inside other rings as if turned over "
                                     "(a groundplan bug; please report)"});
  }
  std::vector<R> outers, holes;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    auto& p = parts[i];
    const int o = ring_orientation(p);
    if (o == 0) continue;
    R r{std::move(p), part_src[i], Box{}, 0, parts_snapped[i] != 0};
    for (const Point2& q : r.pts) r.box.add(q);
    r.area2 = signed_area2(r.pts);
    (o > 0 ? outers : holes).push_back(std::move(r));
  }
  // innermost outer ring containing p (by a vertex not on its boundary)
  auto locate = [&](const std::vector<Point2>& pts, std::size_t skip_outer) -> std::size_t {
    std::size_t best = outers.size();
    for (std::size_t k = 0; k < outers.size(); ++k) {
      if (k == skip_outer) continue;
      const R& o = outers[k];
      int inside = 0;
      for (const Point2& p : pts) {
        if (!o.box.contains(p)) {
          inside = -1;
          break;
        }
        inside = point_in_ring(p, o.pts);
        if (inside != 0) break;
      }
      if (inside > 0 && (best == outers.size() || std::fabs(o.area2) < std::fabs(outers[best].area2))) best = k;
    }
    return best;
  };
  std::vector<std::vector<std::size_t>> holes_of(outers.size());
  for (std::size_t h = 0; h < holes.size(); ++h) {
    const std::size_t k = locate(holes[h].pts, outers.size());
    if (k == outers.size()) {
      out.problems.push_back(Problem{"", "", "union", "ORPHAN_HOLE",
                                     "a hole of the union was found outside every outer ring and was dropped"});
      continue;
    }
    holes_of[k].push_back(h);
  }
  std::vector<std::vector<std::uint32_t>> polys_of(outers.size());
  std::vector<char> poly_seen(polys_.size(), 0);
  for (std::size_t k = 0; k < outers.size(); ++k) {
    auto add = [&](std::size_t src) {
      for (std::uint32_t p : parts_polys[src]) {
        polys_of[k].push_back(p);
        poly_seen[p] = 1;
      }
    };
    add(outers[k].src);
    for (std::size_t h : holes_of[k]) add(holes[h].src);
  }
  // Polygons with area but no boundary piece lie inside the union: find their plan by a vertex.
  for (std::uint32_t p = 0; p < polys_.size(); ++p) {
    if (poly_seen[p] || !polys_[p].has_area) continue;
    // its vertices may all lie on the union's boundary (a triangle inscribed in a square): its
    // edges' midpoints are then inside (an unwalked edge has no boundary piece)
    std::vector<Point2> pts;
    for (std::uint32_t ei = polys_[p].first_edge; ei < polys_[p].end_edge && pts.size() < 8; ++ei)
      pts.push_back(edges_[ei].p0);
    for (std::uint32_t ei = polys_[p].first_edge; ei < polys_[p].end_edge && pts.size() < 16; ++ei)
      pts.push_back({0.5 * (edges_[ei].p0.x + edges_[ei].p1.x), 0.5 * (edges_[ei].p0.y + edges_[ei].p1.y)});
    const std::size_t k = locate(pts, outers.size());
    if (k < outers.size()) polys_of[k].push_back(p);
  }
  for (std::size_t k = 0; k < outers.size(); ++k) {
    GroundPlan g;
    g.polygon.outer = std::move(outers[k].pts);
    long double a2 = outers[k].area2;
    for (std::size_t h : holes_of[k]) {
      a2 += holes[h].area2;
      g.polygon.holes.push_back(std::move(holes[h].pts));
    }
    // Snapped plans are valid by construction (docs/union_engine.md); checked exactly all the same,
    // as the last resort: a conflict would be a bug, reported, never repaired by distorting the plan.
    bool snapped = outers[k].snapped;
    for (std::size_t h : holes_of[k]) snapped |= holes[h].snapped;
    if (snapped) {
      std::vector<std::vector<Point2>*> rr{&g.polygon.outer};
      for (Ring& h : g.polygon.holes) rr.push_back(&h);
      Conflict c{};
      if (find_conflict(rr, c)) {
        const Point2& p = (*rr[c.ring_a])[c.edge_a % rr[c.ring_a]->size()];
        out.problems.push_back(Problem{"", "", "union", "ROUNDING_INVALID",
                                       "a snap-rounded plan crosses itself near (" + std::to_string(p.x) + ", " +
                                           std::to_string(p.y) + ") (a groundplan bug; please report)"});
      }
    }
    g.area_m2 = static_cast<double>(a2 / 2);
    for (std::uint32_t p : polys_of[k]) g.members.push_back(polys_[p].footprint);
    std::sort(g.members.begin(), g.members.end());
    g.members.erase(std::unique(g.members.begin(), g.members.end()), g.members.end());
    out.plans.push_back(std::move(g));
  }
}

}  // namespace groundplan::detail

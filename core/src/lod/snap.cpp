// SPDX-License-Identifier: MIT
// --snap (issue 9): make almost-touching walls share their vertices exactly, before the union.
//
// Two passes over the footprints, both in priority order (footprint, polygon, ring, vertex):
//   1. Vertex clustering, greedy: a vertex within tol of a kept vertex moves onto the nearest one,
//      otherwise it becomes a kept vertex itself. Kept vertices are therefore more than tol apart,
//      and a vertex is compared with kept vertices only, never with moved ones: no chaining, so
//      each vertex moves at most tol.
//   2. Edge insertion: into every edge (a, b) goes every kept vertex v != a, b within tol of the
//      segment, v itself (not its projection), ordered along the edge. A wall that passes 0.3 mm
//      from a neighbour's corner then holds that corner exactly, and the exact union joins them.
//      Every inserted v lies strictly inside the edge's parameter range: a point beyond an endpoint
//      is nearer to that endpoint than tol would allow (kept vertices are > tol apart).
// Then consecutive repeated points go, and rings with fewer than 3 distinct points are dropped.
// Non-finite points are left where they are (the union engine reports them) and take no part.
//
// Spatial index. Clustering uses a hash grid of cell 2.5 tol over the kept vertices: a query looks
// at 2x2 cells, and since kept vertices are > tol apart each cell holds a few dozen at most, however
// dense the input. Edge insertion needs a coarser grid (a cell of tol would make a 20 m wall visit
// 20,000 cells at tol = 1 mm): cells of about the median edge length, and a long edge is cut into
// pieces of at most one cell, each piece querying the cells of its box grown by tol.
#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "lod/ring_geometry.h"
#include "robust/coordinate_range.h"

namespace groundplan {
namespace {

// Points the exact arithmetic refuses (NaN, inf, 1e300, subnormal: robust/coordinate_range.h) stay as they are.
bool finite(const Point2& p) { return robust::admissible(p); }

double dist2(const Point2& a, const Point2& b) {
  const double dx = a.x - b.x, dy = a.y - b.y;
  return dx * dx + dy * dy;
}

using lod::segment_distance2;

/// Open-addressing map from a grid cell to a value (the head of a list, or a range start): much
/// faster than std::unordered_map for the million lookups of a city.
class CellMap {
 public:
  explicit CellMap(std::size_t expected) {
    std::size_t cap = 256;
    while (cap < expected * 2) cap <<= 1;
    keys_.assign(cap, kEmpty);
    vals_.assign(cap, 0);
    mask_ = cap - 1;
  }
  static std::uint64_t key(std::int64_t cx, std::int64_t cy) {
    return (static_cast<std::uint64_t>(cx) * 0x9E3779B97F4A7C15ull) ^ static_cast<std::uint64_t>(cy);
  }
  /// The slot of (cx, cy), created with `init` if absent.
  std::uint32_t& at(std::int64_t cx, std::int64_t cy, std::uint32_t init) {
    if (size_ * 2 >= keys_.size()) grow();
    return vals_[insert(cx, cy, init)];
  }
  const std::uint32_t* find(std::int64_t cx, std::int64_t cy) const {
    std::size_t i = hash(cx, cy) & mask_;
    for (;;) {
      if (keys_[i].cx == kEmpty.cx && keys_[i].cy == kEmpty.cy) return nullptr;
      if (keys_[i].cx == cx && keys_[i].cy == cy) return &vals_[i];
      i = (i + 1) & mask_;
    }
  }

 private:
  struct Key {
    std::int64_t cx, cy;
  };
  // Cell coordinates are clamped well inside +-2^62 (see Grid), so this key never occurs.
  static constexpr Key kEmpty{std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::min()};
  // Cells of one 16 x 16 tile get consecutive slots: input vertices come in spatial runs (a
  // building, a block), so neighbouring lookups share cache lines instead of missing every time.
  static std::size_t hash(std::int64_t cx, std::int64_t cy) {
    std::uint64_t h = key(cx >> 4, cy >> 4);
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    return static_cast<std::size_t>((h << 8) | (static_cast<std::uint64_t>(cx & 15) << 4) | static_cast<std::uint64_t>(cy & 15));
  }
  std::size_t insert(std::int64_t cx, std::int64_t cy, std::uint32_t init) {
    std::size_t i = hash(cx, cy) & mask_;
    for (;;) {
      if (keys_[i].cx == kEmpty.cx && keys_[i].cy == kEmpty.cy) {
        keys_[i] = {cx, cy};
        vals_[i] = init;
        ++size_;
        return i;
      }
      if (keys_[i].cx == cx && keys_[i].cy == cy) return i;
      i = (i + 1) & mask_;
    }
  }
  void grow() {
    std::vector<Key> old_keys = std::move(keys_);
    std::vector<std::uint32_t> old_vals = std::move(vals_);
    keys_.assign(old_keys.size() * 2, kEmpty);
    vals_.assign(old_keys.size() * 2, 0);
    mask_ = keys_.size() - 1;
    size_ = 0;
    for (std::size_t i = 0; i < old_keys.size(); ++i)
      if (!(old_keys[i].cx == kEmpty.cx && old_keys[i].cy == kEmpty.cy))
        vals_[insert(old_keys[i].cx, old_keys[i].cy, 0)] = old_vals[i];
  }
  std::vector<Key> keys_;
  std::vector<std::uint32_t> vals_;
  std::size_t mask_ = 0, size_ = 0;
};

/// Cell coordinates about a local origin; clamped so that absurd coordinates cannot overflow.
struct Grid {
  Point2 origin;
  double cell = 1;
  std::int64_t cx(double x) const { return clampi(std::floor((x - origin.x) / cell)); }
  std::int64_t cy(double y) const { return clampi(std::floor((y - origin.y) / cell)); }
  static std::int64_t clampi(double v) { return static_cast<std::int64_t>(std::clamp(v, -0x1p60, 0x1p60)); }
};

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

/// Keeps rings with at least 3 distinct points: a ring that only alternates between two points
/// (A B A B) encloses nothing.
bool has_three_distinct(const Ring& r) {
  if (r.size() < 3) return false;
  std::size_t i = 1;
  while (i < r.size() && r[i] == r[0]) ++i;
  if (i == r.size()) return false;
  const Point2 q = r[i];
  for (; i < r.size(); ++i)
    if (!(r[i] == r[0]) && !(r[i] == q)) return true;
  return false;
}

/// Removes consecutive repeated points, including the wrap-around.
void dedupe(Ring& r) {
  if (r.empty()) return;
  std::size_t w = 1;
  for (std::size_t i = 1; i < r.size(); ++i)
    if (!(r[i] == r[w - 1])) r[w++] = r[i];
  r.resize(w);
  while (r.size() > 1 && r.back() == r.front()) r.pop_back();
}

}  // namespace

std::vector<Footprint> snap_footprints(const std::vector<Footprint>& footprints, double tolerance_m,
                                       LodStats* stats) {
  if (!(tolerance_m > 0) || !std::isfinite(tolerance_m)) {
    std::ostringstream msg;
    msg << "snap tolerance must be a positive finite distance in metres, got " << tolerance_m;
    throw InvalidArgument(msg.str());
  }
  const auto t0 = std::chrono::steady_clock::now();
  const double tol = tolerance_m, tol2 = tol * tol;

  // Extent and edge lengths of the finite input, for the grids.
  Point2 origin{0, 0};
  bool have_origin = false;
  double max_abs = 0;
  std::size_t n_points = 0;
  std::vector<double> edge_len;
  for (const Footprint& f : footprints)
    for (const Polygon& poly : f.polygons)
      for (int k = -1; k < static_cast<int>(poly.holes.size()); ++k) {
        const Ring& r = k < 0 ? poly.outer : poly.holes[k];
        n_points += r.size();
        for (std::size_t i = 0; i < r.size(); ++i) {
          const Point2& p = r[i];
          if (!finite(p)) continue;
          if (!have_origin) origin = p, have_origin = true;
          max_abs = std::max({max_abs, std::abs(p.x - origin.x), std::abs(p.y - origin.y)});
          // A sample of edges is enough for a median.
          if ((i & 3) == 0) {
            const Point2& q = r[(i + 1) % r.size()];
            if (finite(q) && !(p == q)) edge_len.push_back(std::sqrt(dist2(p, q)));
          }
        }
      }

  // Cells of 2.5 tol: the disk of radius tol about a point then lies in the 2x2 cells nearest to it
  // (with a tenth of a cell to spare for rounding), 4 lookups instead of 9. At least 2^-40 of the
  // extent, so that a tiny tol on large coordinates keeps cell indices small.
  Grid vgrid{origin, std::max(2.5 * tol, max_abs * 0x1p-40)};
  if (!(vgrid.cell > 0)) vgrid.cell = 1;

  // Pass 1: clustering. Each input point gets the index of its kept vertex (kNone: non-finite).
  std::vector<Point2> kept;
  std::vector<std::uint32_t> next_in_cell;  // per kept vertex: the next one in its cell
  std::vector<std::uint32_t> target;        // per input point, in priority order
  kept.reserve(n_points / 2 + 1);
  target.reserve(n_points);
  CellMap vcells(n_points / 2 + 1);
  std::size_t moved = 0;
  for (const Footprint& f : footprints)
    for (const Polygon& poly : f.polygons)
      for (int k = -1; k < static_cast<int>(poly.holes.size()); ++k) {
        const Ring& r = k < 0 ? poly.outer : poly.holes[k];
        for (const Point2& p : r) {
          if (!finite(p)) {
            target.push_back(kNone);
            continue;
          }
          const double fx = (p.x - origin.x) / vgrid.cell, fy = (p.y - origin.y) / vgrid.cell;
          const std::int64_t cx = Grid::clampi(std::floor(fx)), cy = Grid::clampi(std::floor(fy));
          const std::int64_t nx = fx - std::floor(fx) < 0.5 ? -1 : 1, ny = fy - std::floor(fy) < 0.5 ? -1 : 1;
          std::uint32_t best = kNone;
          double best_d2 = 0;
          for (const std::int64_t dx : {std::int64_t{0}, nx})
            for (const std::int64_t dy : {std::int64_t{0}, ny}) {
              const std::uint32_t* head = vcells.find(cx + dx, cy + dy);
              for (std::uint32_t v = head ? *head : kNone; v != kNone; v = next_in_cell[v]) {
                const double d2 = dist2(p, kept[v]);
                // Nearest; on a tie the earlier kept vertex, so the result does not depend on cells.
                if (d2 <= tol2 && (best == kNone || d2 < best_d2 || (d2 == best_d2 && v < best))) best = v, best_d2 = d2;
              }
            }
          if (best == kNone) {
            if (kept.size() >= kNone - 1) throw Error("snap_footprints: too many vertices (more than 2^32)");
            best = static_cast<std::uint32_t>(kept.size());
            kept.push_back(p);
            std::uint32_t& head = vcells.at(cx, cy, kNone);
            next_in_cell.push_back(head);
            head = best;
          } else if (!(kept[best] == p)) {
            ++moved;
          }
          target.push_back(best);
        }
      }

  // Pass 2's grid: kept vertices sorted by coarse cell (counting sort); a cell maps to its id c,
  // and its vertices are cell_items[start[c] .. start[c + 1]).
  double median = 0;
  if (!edge_len.empty()) {
    auto mid = edge_len.begin() + static_cast<std::ptrdiff_t>(edge_len.size() / 2);
    std::nth_element(edge_len.begin(), mid, edge_len.end());
    median = *mid;
  }
  const Grid egrid{origin, std::max({vgrid.cell, 2 * tol, median})};
  std::vector<std::uint32_t> cell_items(kept.size());
  std::vector<std::uint32_t> start;
  CellMap ecells(kept.size() / 2 + 1);
  {
    std::vector<std::uint32_t> slot(kept.size());
    std::vector<std::uint32_t> count;
    for (std::uint32_t v = 0; v < kept.size(); ++v) {
      std::uint32_t& c = ecells.at(egrid.cx(kept[v].x), egrid.cy(kept[v].y), kNone);
      if (c == kNone) {
        c = static_cast<std::uint32_t>(count.size());
        count.push_back(0);
      }
      slot[v] = c;
      ++count[c];
    }
    start.assign(count.size() + 1, 0);
    for (std::size_t c = 0; c < count.size(); ++c) start[c + 1] = start[c] + count[c];
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::uint32_t v = 0; v < kept.size(); ++v) cell_items[fill[slot[v]]++] = v;
  }

  // Kept vertices within tol of the segment kept[ia] - kept[ib], in order along it.
  std::vector<std::uint32_t> cand;
  std::vector<std::pair<double, std::uint32_t>> hits;
  auto on_edge = [&](std::uint32_t ia, std::uint32_t ib) {
    hits.clear();
    cand.clear();
    const Point2 a = kept[ia], b = kept[ib];
    const double len = std::sqrt(dist2(a, b));
    // Pieces of at most one cell, each with its box grown by tol and a little rounding slack.
    const auto pieces = static_cast<std::size_t>(std::min(1e6, std::ceil(len / egrid.cell))) + 1;
    const double slack = tol + 1e-12 * (max_abs + egrid.cell);
    for (std::size_t k = 0; k < pieces; ++k) {
      const double t0p = static_cast<double>(k) / pieces, t1p = static_cast<double>(k + 1) / pieces;
      const double x0 = a.x + t0p * (b.x - a.x), x1 = a.x + t1p * (b.x - a.x);
      const double y0 = a.y + t0p * (b.y - a.y), y1 = a.y + t1p * (b.y - a.y);
      const std::int64_t cx0 = egrid.cx(std::min(x0, x1) - slack), cx1 = egrid.cx(std::max(x0, x1) + slack);
      const std::int64_t cy0 = egrid.cy(std::min(y0, y1) - slack), cy1 = egrid.cy(std::max(y0, y1) + slack);
      for (std::int64_t cx = cx0; cx <= cx1; ++cx)
        for (std::int64_t cy = cy0; cy <= cy1; ++cy)
          if (const std::uint32_t* c = ecells.find(cx, cy))
            for (std::uint32_t j = start[*c]; j < start[*c + 1]; ++j) cand.push_back(cell_items[j]);
    }
    if (pieces > 1) {
      std::sort(cand.begin(), cand.end());
      cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    }
    const double ux = b.x - a.x, uy = b.y - a.y, len2 = ux * ux + uy * uy;
    for (std::uint32_t v : cand) {
      if (v == ia || v == ib) continue;
      const Point2& p = kept[v];
      if (segment_distance2(p, a, b) <= tol2) hits.emplace_back(((p.x - a.x) * ux + (p.y - a.y) * uy) / len2, v);
    }
    std::sort(hits.begin(), hits.end());
  };

  // Pass 2: rebuild every ring from its kept vertices, with insertions, in the same order as pass 1.
  std::vector<Footprint> out;
  out.reserve(footprints.size());
  std::size_t inserted = 0, collapsed = 0, pos = 0;
  std::vector<std::uint32_t> ids;
  auto rebuild = [&](const Ring& r, Ring& dst) {
    ids.assign(target.begin() + static_cast<std::ptrdiff_t>(pos), target.begin() + static_cast<std::ptrdiff_t>(pos + r.size()));
    dst.clear();
    dst.reserve(r.size());
    for (std::size_t i = 0; i < r.size(); ++i) {
      const std::uint32_t ia = ids[i], ib = ids[(i + 1) % r.size()];
      dst.push_back(ia == kNone ? r[i] : kept[ia]);
      if (ia == kNone || ib == kNone || ia == ib) continue;
      on_edge(ia, ib);
      for (const auto& h : hits) dst.push_back(kept[h.second]);
      inserted += hits.size();
    }
    pos += r.size();
    dedupe(dst);
    if (has_three_distinct(dst)) return true;
    ++collapsed;
    return false;
  };
  for (const Footprint& f : footprints) {
    Footprint g;
    g.source_id = f.source_id;
    g.parent_id = f.parent_id;
    g.source_file = f.source_file;
    g.method = f.method;
    g.min_z = f.min_z;
    g.max_z = f.max_z;
    g.polygons.reserve(f.polygons.size());
    for (const Polygon& poly : f.polygons) {
      Polygon q;
      const bool outer_ok = rebuild(poly.outer, q.outer);
      for (const Ring& h : poly.holes) {
        Ring hr;
        if (rebuild(h, hr) && outer_ok) q.holes.push_back(std::move(hr));
      }
      // A polygon whose outer ring collapsed is dropped with its holes (a hole alone covers nothing).
      if (outer_ok) g.polygons.push_back(std::move(q));
    }
    out.push_back(std::move(g));
  }

  if (stats) {
    stats->snap_vertices_moved = moved;
    stats->snap_vertices_inserted = inserted;
    stats->snap_rings_collapsed = collapsed;
    stats->snap_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return out;
}

}  // namespace groundplan

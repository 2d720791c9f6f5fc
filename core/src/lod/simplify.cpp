// SPDX-License-Identifier: MIT
// --simplify (issue 9): topology-preserving Douglas-Peucker on every ring of every plan.
//
// Anchors. A point that occurs in more than one ring, or twice in one ring, is where rings touch
// (plans touching at a point, a hole touching its shell, a ring pinched at a vertex): it stays, and
// the ring is simplified section by section between its anchors. A ring with fewer than two anchors
// gets its leftmost vertex and the vertex farthest from it.
//
// Douglas-Peucker, top down on each section: the shortcut a-b replaces the chain a..b when
//   (i)   every vertex of the chain is within T of the segment a-b (then the chain and the segment
//         are within T of each other both ways: a Hausdorff distance <= T),
//   (ii)  a-b meets no other current edge of any ring except at a shared endpoint, without
//         overlapping it (exact orientation tests),
//   (iii) no vertex of any ring other than the chain's has odd crossing parity with respect to the
//         closed curve chain + b-a, nor lies on it (exact).
// Otherwise the chain splits at its farthest vertex. Every decision is taken against the current
// state of all rings (a grid over edges and vertices, updated as shortcuts are accepted), so the
// plans stay valid at every step: (ii) keeps every ring simple and apart from the others, and
// (iii) keeps every other ring (and the rest of the same ring) on the side of this ring it was on,
// since a ring that crosses neither the chain nor a-b can only change sides through a vertex.
// A ring that would become a point or a line is refused by (ii) (its edges would overlap), so rings
// keep at least 3 vertices; a final orientation check restores the ring if its sign changed.
//
// (i) always measures the original vertices between a and b, never an earlier simplification, so
// the result stays within T of the input ring however the chains were cut.
#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "lod/ring_geometry.h"
#include "robust/predicates.h"

namespace groundplan {
namespace {

using robust::orient;

using lod::segment_distance2;

/// r collinear with p, q: whether it lies on the closed segment p-q (exact: comparisons only).
bool within_box(const Point2& p, const Point2& q, const Point2& r) {
  return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y &&
         r.y <= std::max(p.y, q.y);
}

/// Whether segments a-b and c-d meet anywhere other than at one shared endpoint where they do not
/// overlap. Exact.
bool conflict(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const bool ac = a == c, ad = a == d, bc = b == c, bd = b == d;
  if ((ac && bd) || (ad && bc)) return true;  // the same edge twice: rings would share a wall
  if (ac || ad || bc || bd) {
    const Point2& s = ac || ad ? a : b;  // the shared point
    const Point2& u = ac || ad ? b : a;  // a-b's other end
    const Point2& w = ac || bc ? d : c;  // c-d's other end
    if (orient(s, u, w) != 0) return false;
    // Collinear through s: they overlap when u and w lie on the same side of s.
    if (u.x != s.x) return (u.x > s.x) == (w.x > s.x);
    return (u.y > s.y) == (w.y > s.y);
  }
  const int o1 = orient(a, b, c), o2 = orient(a, b, d);
  if (o1 == 0 && o2 == 0)
    return within_box(a, b, c) || within_box(a, b, d) || within_box(c, d, a) || within_box(c, d, b);
  if (o1 * o2 > 0) return false;
  const int o3 = orient(c, d, a), o4 = orient(c, d, b);
  return o3 * o4 <= 0;
}

/// Open-addressing map from a grid cell to a bucket index (faster than std::unordered_map for the
/// millions of lookups of a city).
class CellMap {
 public:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  CellMap() { reset(16); }
  std::uint32_t find(std::int64_t cx, std::int64_t cy) const {
    const std::uint64_t k = pack(cx, cy);
    for (std::size_t i = hash(k) & mask_;; i = (i + 1) & mask_) {
      if (keys_[i] == kEmpty) return kNone;
      if (keys_[i] == k) return vals_[i];
    }
  }
  /// The bucket of (cx, cy), `fresh` if the cell is new.
  std::uint32_t get_or_add(std::int64_t cx, std::int64_t cy, std::uint32_t fresh) {
    if (size_ * 2 >= keys_.size()) grow();
    const std::uint64_t k = pack(cx, cy);
    for (std::size_t i = hash(k) & mask_;; i = (i + 1) & mask_) {
      if (keys_[i] == k) return vals_[i];
      if (keys_[i] == kEmpty) {
        keys_[i] = k;
        vals_[i] = fresh;
        ++size_;
        return fresh;
      }
    }
  }

 private:
  static constexpr std::uint64_t kEmpty = ~0ull;
  // Cell indices are clamped to +-2^30 (Grid::clampi), so each fits 32 bits once biased by 2^31; the
  // bias keeps both halves within [2^30, 3 * 2^30], so no cell packs to kEmpty. (Unbiased, the cell
  // (-1, -1), down-left of the grid's origin, packed to ~0 = kEmpty: what was put there could never be
  // found, so a shortcut there saw none of the edges it crossed: fuzz_lod's b16fa889.)
  static std::uint64_t pack(std::int64_t cx, std::int64_t cy) {
    constexpr std::int64_t kBias = std::int64_t{1} << 31;
    return (static_cast<std::uint64_t>(cx + kBias) << 32) | static_cast<std::uint64_t>(cy + kBias);
  }
  static std::size_t hash(std::uint64_t h) {
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return static_cast<std::size_t>(h);
  }
  void reset(std::size_t cap) {
    keys_.assign(cap, kEmpty);
    vals_.assign(cap, 0);
    mask_ = cap - 1;
    size_ = 0;
  }
  void grow() {
    std::vector<std::uint64_t> ok = std::move(keys_);
    std::vector<std::uint32_t> ov = std::move(vals_);
    reset(ok.size() * 2);
    for (std::size_t j = 0; j < ok.size(); ++j) {
      if (ok[j] == kEmpty) continue;
      std::size_t i = hash(ok[j]) & mask_;
      while (keys_[i] != kEmpty) i = (i + 1) & mask_;
      keys_[i] = ok[j];
      vals_[i] = ov[j];
      ++size_;
    }
  }
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> vals_;
  std::size_t mask_ = 0, size_ = 0;
};

/// A uniform hash grid of vertices (in their cell) and edges (in every cell they pass through).
/// Removal is a flag on the item, checked by the caller: buckets only grow.
class Grid {
 public:
  Grid(Point2 origin, double cell, double slack) : origin_(origin), cell_(cell), slack_(slack) {}

  void add_vertex(std::uint32_t id, const Point2& p) {
    vbuckets(bucket(cx(p.x), cy(p.y))).push_back(id);
  }
  void add_edge(std::uint32_t id, const Point2& p, const Point2& q) {
    last_bucket_ = CellMap::kNone;
    along(p, q, slack_, [&](std::int64_t x, std::int64_t y) {
      const std::uint32_t b = bucket(x, y);
      if (b == last_bucket_) return;  // consecutive pieces often share a cell
      std::vector<std::uint32_t>& e = ebuckets(b);
      if (e.empty() || e.back() != id) e.push_back(id);
      last_bucket_ = b;
    });
  }
  /// Calls f(bucket) for every non-empty cell within `grow` of the segment p-q (a cell may come twice).
  template <class F>
  void cells_near(const Point2& p, const Point2& q, double grow, F&& f) const {
    along(p, q, grow + slack_, [&](std::int64_t x, std::int64_t y) {
      const std::uint32_t b = map_.find(x, y);
      if (b != CellMap::kNone) f(b);
    });
  }
  const std::vector<std::uint32_t>& vertices_in(std::uint32_t b) const { return verts_[b]; }
  const std::vector<std::uint32_t>& edges_in(std::uint32_t b) const { return edges_[b]; }

 private:
  std::int64_t cx(double x) const { return clampi(std::floor((x - origin_.x) / cell_)); }
  std::int64_t cy(double y) const { return clampi(std::floor((y - origin_.y) / cell_)); }
  static std::int64_t clampi(double v) { return static_cast<std::int64_t>(std::clamp(v, -0x1p30, 0x1p30)); }
  std::uint32_t bucket(std::int64_t x, std::int64_t y) {
    const std::uint32_t b = map_.get_or_add(x, y, static_cast<std::uint32_t>(verts_.size()));
    if (b == verts_.size()) {
      verts_.emplace_back();
      edges_.emplace_back();
    }
    return b;
  }
  std::vector<std::uint32_t>& vbuckets(std::uint32_t b) { return verts_[b]; }
  std::vector<std::uint32_t>& ebuckets(std::uint32_t b) { return edges_[b]; }
  /// The cells of the segment's box grown by `grow`, piece by piece (pieces of at most one cell, so
  /// that a long diagonal does not visit the whole box).
  template <class F>
  void along(const Point2& p, const Point2& q, double grow, F&& f) const {
    const double len = std::hypot(q.x - p.x, q.y - p.y);
    const auto pieces = static_cast<std::size_t>(std::min(1e6, std::ceil(len / cell_))) + 1;
    for (std::size_t k = 0; k < pieces; ++k) {
      const double t0 = static_cast<double>(k) / pieces, t1 = static_cast<double>(k + 1) / pieces;
      const double x0 = p.x + t0 * (q.x - p.x), x1 = p.x + t1 * (q.x - p.x);
      const double y0 = p.y + t0 * (q.y - p.y), y1 = p.y + t1 * (q.y - p.y);
      const std::int64_t ax = cx(std::min(x0, x1) - grow), bx = cx(std::max(x0, x1) + grow);
      const std::int64_t ay = cy(std::min(y0, y1) - grow), by = cy(std::max(y0, y1) + grow);
      for (std::int64_t x = ax; x <= bx; ++x)
        for (std::int64_t y = ay; y <= by; ++y) f(x, y);
    }
  }
  Point2 origin_;
  double cell_, slack_;
  CellMap map_;
  std::vector<std::vector<std::uint32_t>> verts_, edges_;
  std::uint32_t last_bucket_ = CellMap::kNone;
};

struct Edge {
  Point2 p, q;
  bool alive = true;
};

double ring_area2(const Ring& r) { return static_cast<double>(lod::ring_area2(r)); }

class Simplifier {
 public:
  Simplifier(const std::vector<GroundPlan>& plans, double tol) : tol_(tol), tol2_(tol * tol) {
    // Rings in a flat list; vertex g of ring r has global id start_[r] + i, and the original edge
    // from it to the next vertex has the same id.
    for (const GroundPlan& p : plans) {
      rings_.push_back(&p.polygon.outer);
      for (const Ring& h : p.polygon.holes) rings_.push_back(&h);
    }
    start_.assign(rings_.size() + 1, 0);
    for (std::size_t r = 0; r < rings_.size(); ++r) start_[r + 1] = start_[r] + rings_[r]->size();
    const std::size_t nv = start_.back();
    if (nv >= std::numeric_limits<std::uint32_t>::max() / 2)
      throw Error("simplify_plans: too many vertices (more than 2^31)");
    vertex_alive_.assign(nv, 1);
    edges_.reserve(nv + nv / 4);
    Point2 origin{0, 0};
    double extent = 0;
    std::vector<double> lens;
    for (std::size_t r = 0; r < rings_.size(); ++r) {
      const Ring& ring = *rings_[r];
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const Point2& p = ring[i];
        const Point2& q = ring[(i + 1) % ring.size()];
        edges_.push_back({p, q, true});
        if (r == 0 && i == 0) origin = p;
        extent = std::max({extent, std::abs(p.x - origin.x), std::abs(p.y - origin.y)});
        if ((i & 3) == 0) lens.push_back(std::hypot(q.x - p.x, q.y - p.y));
      }
    }
    double median = 0;
    if (!lens.empty()) {
      auto mid = lens.begin() + static_cast<std::ptrdiff_t>(lens.size() / 2);
      std::nth_element(lens.begin(), mid, lens.end());
      median = *mid;
    }
    // Cells of about one edge, at least 2T (a query grown by T then covers at most 3x3 cells per
    // piece), and at least 2^-28 of the extent (cell indices stay within 32 bits).
    double cell = std::max({median, 2 * tol, extent * 0x1p-28});
    if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
    grid_.emplace(origin, cell, 1e-9 * (extent + cell));
    for (std::size_t r = 0; r < rings_.size(); ++r) {
      const Ring& ring = *rings_[r];
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const auto g = static_cast<std::uint32_t>(start_[r] + i);
        grid_->add_vertex(g, ring[i]);
        grid_->add_edge(g, edges_[g].p, edges_[g].q);
      }
    }
    edge_stamp_.assign(edges_.size(), 0);
    vertex_stamp_.assign(nv, 0);
    find_anchors();
  }

  /// Simplifies every ring in order; returns the kept vertices of ring r.
  void run() {
    kept_.resize(rings_.size());
    for (std::size_t r = 0; r < rings_.size(); ++r) simplify_ring(r);
  }
  const std::vector<Point2>& kept(std::size_t r) const { return kept_[r]; }
  std::size_t ring_count() const { return rings_.size(); }

 private:
  /// A point that occurs more than once over all rings is an anchor (sorting finds the repeats).
  void find_anchors() {
    std::vector<std::pair<Point2, std::uint32_t>> pts;
    pts.reserve(vertex_alive_.size());
    for (std::size_t r = 0; r < rings_.size(); ++r)
      for (std::size_t i = 0; i < rings_[r]->size(); ++i)
        pts.emplace_back((*rings_[r])[i], static_cast<std::uint32_t>(start_[r] + i));
    std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) {
      return a.first.x < b.first.x || (a.first.x == b.first.x && a.first.y < b.first.y);
    });
    anchor_.assign(vertex_alive_.size(), 0);
    for (std::size_t i = 0; i < pts.size();) {
      std::size_t j = i + 1;
      while (j < pts.size() && pts[j].first == pts[i].first) ++j;
      if (j - i > 1)
        for (std::size_t k = i; k < j; ++k) anchor_[pts[k].second] = 1;
      i = j;
    }
  }

  void simplify_ring(std::size_t r) {
    const Ring& ring = *rings_[r];
    const std::size_t n = ring.size();
    std::vector<std::size_t> anchors;
    for (std::size_t i = 0; i < n; ++i)
      if (anchor_[start_[r] + i]) anchors.push_back(i);
    if (n < 4) {  // a triangle (or something invalid) has nothing to remove
      kept_[r] = ring;
      return;
    }
    // Fewer than two anchors: the leftmost vertex (if needed) and the one farthest from the first.
    // They are only where the ring is cut open; once the rest is done they may go too (below).
    std::vector<std::size_t> forced;
    if (anchors.empty()) {
      std::size_t lo = 0;
      for (std::size_t i = 1; i < n; ++i)
        if (ring[i].x < ring[lo].x || (ring[i].x == ring[lo].x && ring[i].y < ring[lo].y)) lo = i;
      anchors.push_back(lo);
      forced.push_back(lo);
    }
    if (anchors.size() == 1) {
      const Point2& a = ring[anchors[0]];
      std::size_t far = anchors[0];
      double best = -1;
      for (std::size_t i = 0; i < n; ++i) {
        const double d = std::hypot(ring[i].x - a.x, ring[i].y - a.y);
        if (d > best) best = d, far = i;
      }
      if (far != anchors[0]) {
        anchors.push_back(far);
        forced.push_back(far);
      }
      std::sort(anchors.begin(), anchors.end());
    }
    removed_.assign(n, 0);
    out_edge_.resize(n);
    for (std::size_t i = 0; i < n; ++i) out_edge_[i] = static_cast<std::uint32_t>(start_[r] + i);
    new_edges_.clear();
    // Sections between consecutive anchors, positions taken modulo n.
    for (std::size_t k = 0; k < anchors.size(); ++k) {
      const std::size_t i = anchors[k];
      const std::size_t j = k + 1 < anchors.size() ? anchors[k + 1] : anchors[0] + n;
      stack_.clear();
      stack_.emplace_back(i, j);
      while (!stack_.empty()) {
        const auto [a, b] = stack_.back();
        stack_.pop_back();
        if (b - a < 2) continue;
        const std::size_t split = try_shortcut(r, a, b);
        if (split == 0) continue;  // accepted
        stack_.emplace_back(split, b);
        stack_.emplace_back(a, split);  // the front half first (top of the stack)
      }
    }
    // A cut point may go when the chain between its kept neighbours passes every test (measured
    // against the original vertices in between, like any other chain).
    for (const std::size_t f : forced) {
      std::size_t kept_count = 0;
      for (std::size_t i = 0; i < n; ++i) kept_count += !removed_[i];
      if (kept_count <= 3) break;
      // Unrolled positions a < f + n < b + n: the kept neighbours before and after f.
      std::size_t a = f + n - 1, b = f + 1;
      while (removed_[a % n]) --a;
      while (removed_[b % n]) ++b;
      try_shortcut(r, a, b + n);
    }
    std::vector<Point2> out;
    out.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
      if (!removed_[i]) out.push_back(ring[i]);
    // The checks keep the ring simple and non-degenerate; its orientation cannot change without a
    // crossing, but a wrong sign here would make the plan invalid, so it is checked.
    const double before = ring_area2(ring), after = ring_area2(out);
    if (out.size() < 3 || !(after != 0) || (after > 0) != (before > 0)) {
      restore(r);
      out = ring;
    }
    kept_[r] = std::move(out);
  }

  /// Undoes every shortcut of ring r (its original edges and vertices come back).
  void restore(std::size_t r) {
    const std::size_t n = rings_[r]->size();
    for (std::size_t i = 0; i < n; ++i) {
      vertex_alive_[start_[r] + i] = 1;
      edges_[start_[r] + i].alive = true;
    }
    for (std::uint32_t e : new_edges_) edges_[e].alive = false;
  }

  /// The chain of ring r from position a to position b (b - a >= 2, modulo n): replaces it by the
  /// segment and returns 0, or returns the position to split at.
  std::size_t try_shortcut(std::size_t r, std::size_t a, std::size_t b) {
    const Ring& ring = *rings_[r];
    const std::size_t n = ring.size();
    const Point2& pa = ring[a % n];
    const Point2& pb = ring[b % n];
    std::size_t far = a + 1;
    double far_d2 = -1;
    for (std::size_t i = a + 1; i < b; ++i) {
      const double d2 = pa == pb ? (ring[i % n].x - pa.x) * (ring[i % n].x - pa.x) + (ring[i % n].y - pa.y) * (ring[i % n].y - pa.y)
                                 : segment_distance2(ring[i % n], pa, pb);
      if (d2 > far_d2) far_d2 = d2, far = i;
    }
    // A chain from a point back to itself (a pinched loop) never becomes a zero-length edge.
    if (pa == pb || !(far_d2 <= tol2_)) return far;
    const std::size_t g0 = start_[r];
    // The chain's current edges and vertices (the kept ones between a and b) leave for the tests,
    // and come back if refused.
    auto set_chain = [&](bool alive) {
      for (std::size_t i = a; i < b; ++i) {
        if (removed_[i % n]) continue;
        edges_[out_edge_[i % n]].alive = alive;
        if (i > a) vertex_alive_[g0 + i % n] = alive;
      }
    };
    set_chain(false);
    if (!(free_of_edges(pa, pb) && free_of_vertices(ring, a, b))) {
      set_chain(true);
      return far;
    }
    for (std::size_t i = a + 1; i < b; ++i) removed_[i % n] = 1;
    const auto e = static_cast<std::uint32_t>(edges_.size());
    edges_.push_back({pa, pb, true});
    edge_stamp_.push_back(0);
    grid_->add_edge(e, pa, pb);
    new_edges_.push_back(e);
    out_edge_[a % n] = e;
    return 0;
  }

  /// (ii): no live edge meets a-b other than at a shared endpoint without overlap.
  bool free_of_edges(const Point2& a, const Point2& b) {
    ++stamp_;
    bool ok = true;
    grid_->cells_near(a, b, 0, [&](std::uint32_t bucket) {
      if (!ok) return;
      for (std::uint32_t e : grid_->edges_in(bucket)) {
        if (edge_stamp_[e] == stamp_) continue;
        edge_stamp_[e] = stamp_;
        const Edge& ed = edges_[e];
        if (ed.alive && conflict(a, b, ed.p, ed.q)) {
          ok = false;
          return;
        }
      }
    });
    return ok;
  }

  /// (iii): no live vertex other than a and b lies inside (odd parity) or on the closed curve made
  /// of the chain a..b and the segment b-a. The curve lies within T of a-b, so only the cells of
  /// that band are looked at.
  bool free_of_vertices(const Ring& ring, std::size_t a, std::size_t b) {
    const std::size_t n = ring.size();
    const Point2& pa = ring[a % n];
    const Point2& pb = ring[b % n];
    double minx = pa.x, maxx = pa.x, miny = pa.y, maxy = pa.y;
    for (std::size_t i = a + 1; i <= b; ++i) {
      if (removed_[i % n]) continue;
      const Point2& p = ring[i % n];
      minx = std::min(minx, p.x), maxx = std::max(maxx, p.x);
      miny = std::min(miny, p.y), maxy = std::max(maxy, p.y);
    }
    ++stamp_;
    bool ok = true;
    grid_->cells_near(pa, pb, tol_, [&](std::uint32_t bucket) {
      if (!ok) return;
      for (std::uint32_t v : grid_->vertices_in(bucket)) {
        if (vertex_stamp_[v] == stamp_ || !vertex_alive_[v]) continue;
        vertex_stamp_[v] = stamp_;
        const Point2& p = point(v);
        if (p.x < minx || p.x > maxx || p.y < miny || p.y > maxy || p == pa || p == pb) continue;
        if (inside_or_on(ring, a, b, p)) {
          ok = false;
          return;
        }
      }
    });
    return ok;
  }

  /// Whether p is on, or has odd crossing parity with respect to, the closed curve made of the
  /// current (kept) vertices of ring[a..b] and b-a.
  bool inside_or_on(const Ring& ring, std::size_t a, std::size_t b, const Point2& p) const {
    const std::size_t n = ring.size();
    bool odd = false;
    for (std::size_t i = a; i <= b; ++i) {
      if (removed_[i % n]) continue;
      std::size_t j = i + 1;
      while (j < b && removed_[j % n]) ++j;
      const Point2& s = ring[i % n];
      const Point2& t = i < b ? ring[j % n] : ring[a % n];
      const int o = orient(s, t, p);
      if (o == 0 && within_box(s, t, p)) return true;
      // A crossing of the ray from p towards +x: the edge straddles p's height (half-open) and p is
      // on its left when it goes up, on its right when it goes down.
      if ((s.y > p.y) != (t.y > p.y) && (o > 0) == (t.y > s.y)) odd = !odd;
    }
    return odd;
  }

  const Point2& point(std::uint32_t g) const { return edges_[g].p; }  // original edge g starts at vertex g

  double tol_, tol2_;
  std::vector<const Ring*> rings_;
  std::vector<std::size_t> start_;
  std::vector<char> vertex_alive_, anchor_, removed_;
  std::vector<Edge> edges_;
  std::vector<std::uint32_t> edge_stamp_, vertex_stamp_, new_edges_;
  std::vector<std::uint32_t> out_edge_;  // per vertex of the current ring: its current outgoing edge
  std::uint32_t stamp_ = 0;
  std::optional<Grid> grid_;
  std::vector<std::pair<std::size_t, std::size_t>> stack_;
  std::vector<std::vector<Point2>> kept_;
};

}  // namespace

std::vector<GroundPlan> simplify_plans(const std::vector<GroundPlan>& plans, double tolerance_m, LodStats* stats) {
  if (!(tolerance_m > 0) || !std::isfinite(tolerance_m)) {
    std::ostringstream msg;
    msg << "simplify tolerance must be a positive finite distance in metres, got " << tolerance_m;
    throw InvalidArgument(msg.str());
  }
  const auto t0 = std::chrono::steady_clock::now();
  Simplifier s(plans, tolerance_m);
  s.run();
  std::vector<GroundPlan> out;
  out.reserve(plans.size());
  std::size_t before = 0, after = 0, r = 0;
  for (const GroundPlan& p : plans) {
    GroundPlan q;
    q.members = p.members;
    before += p.polygon.outer.size();
    q.polygon.outer = s.kept(r++);
    after += q.polygon.outer.size();
    for (const Ring& h : p.polygon.holes) {
      before += h.size();
      q.polygon.holes.push_back(s.kept(r++));
      after += q.polygon.holes.back().size();
    }
    q.area_m2 = polygon_area(q.polygon);
    out.push_back(std::move(q));
  }
  if (stats) {
    stats->simplify_vertices_before = before;
    stats->simplify_vertices_after = after;
    stats->simplify_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return out;
}

}  // namespace groundplan

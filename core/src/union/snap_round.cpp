// SPDX-License-Identifier: MIT
// Snap rounding of one block's boundary (see snap_round.h and docs/union_engine.md).
//
// Pixels are half-open squares [i g, (i+1) g) x [j g, (j+1) g) of the grid of pitch g (a power of
// two); a pixel is hot when it holds a vertex of a walk. The segments rounded are the EXACT walk
// segments: a crossing point is taken where it is exactly (its pixel, and the input edge it lies on),
// not where it is rounded to, because rounded crossings can turn a face of the boundary over (a
// sub-ulp wedge: two rounded walk segments crossing where the exact ones do not), and snap rounding
// keeps what it is given: an edge with union on the left twice. The exact walks of a union do not
// cross, so no crossing makes a pixel hot. Every segment is replaced by the polyline through
// the centres of the hot pixels it meets, in order along it; each piece of that polyline is rerouted
// again while it meets a hot pixel other than its two ends (iterated snap rounding), so that no
// output vertex is closer than g/2 to an output edge it is not on. All tests are exact: a segment
// meets a half-open pixel iff it meets the closed pixel shifted by (-eps, -eps) (separating axes:
// x, y and the segment's normal; robust::orient on doubles, the symbolic shift breaking ties).
// Output vertices are pixel centres, kept as integer pixel coordinates, so angles between grid
// edges are compared in exact integer arithmetic.
#include "union/snap_round.h"
#include "union/box_grid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>
#include <utility>

#include "robust/predicates.h"
#include "union/output_rounding.h"
#include "union/ring_builder.h"

namespace groundplan::detail {
namespace {

/// Distance from p to the closed segment ab (long double: only compared with g/2, far above its error).
long double dist_to_segment(const Point2& p, const Point2& a, const Point2& b) {
  const long double dx = static_cast<long double>(b.x) - a.x, dy = static_cast<long double>(b.y) - a.y;
  const long double px = static_cast<long double>(p.x) - a.x, py = static_cast<long double>(p.y) - a.y;
  const long double l2 = dx * dx + dy * dy;
  long double t = l2 > 0 ? (px * dx + py * dy) / l2 : 0;
  t = std::clamp(t, 0.0L, 1.0L);
  const long double ex = px - t * dx, ey = py - t * dy;
  return std::sqrt(ex * ex + ey * ey);
}

using robust::cross_sign;
using robust::orient;

struct Pix {
  std::int64_t i, j;
  bool operator==(const Pix& o) const { return i == o.i && j == o.j; }
};
struct PixHash {
  std::size_t operator()(const Pix& p) const {
    return std::hash<std::uint64_t>()(static_cast<std::uint64_t>(p.i) * 0x9E3779B97F4A7C15ull ^
                                      static_cast<std::uint64_t>(p.j));
  }
};

class SnapRounder {
 public:
  explicit SnapRounder(double g) : g_(g) {}

  Pix pixel_of(const Point2& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x / g_)), static_cast<std::int64_t>(std::floor(p.y / g_))};
  }
  Point2 centre(std::uint32_t h) const {
    const Pix& p = hot_[h];
    return {(static_cast<double>(p.i) + 0.5) * g_, (static_cast<double>(p.j) + 0.5) * g_};
  }
  void add_hot(const Pix& p) {
    if (index_.emplace(p, static_cast<std::uint32_t>(hot_.size())).second) hot_.push_back(p);
  }
  /// The pixel of a walk vertex, exactly: a crossing point is correctly rounded to `r`, and rounding is
  /// monotone and pixel sides are doubles, so the exact point is in r's pixel unless r lies on the pixel's
  /// left (bottom) side and the exact point left of (below) it.
  Pix exact_pixel(const Point2& r, const ExactVertex* ex) const {
    Pix p = pixel_of(r);
    if (!ex || !ex->cross) return p;
    if (r.x == static_cast<double>(p.i) * g_ && exact_before(*ex, r.x, true)) --p.i;
    if (r.y == static_cast<double>(p.j) * g_ && exact_before(*ex, r.y, false)) --p.j;
    return p;
  }
  /// Whether the crossing of lines a->b and f0->f1 has x < v (`x`), else y < v; exact (compare_crossings
  /// with the grid line x = v or y = v).
  static bool exact_before(const ExactVertex& ex, double v, bool x) {
    const double a = x ? ex.a.x : ex.a.y, b = x ? ex.b.x : ex.b.y;
    const double f0 = x ? ex.f0.x : ex.f0.y, f1 = x ? ex.f1.x : ex.f1.y;
    if (a == b) return a < v;  // the crossing is on this axis-parallel line
    if (f0 == f1) return f0 < v;
    const Point2 g0 = x ? Point2{v, 0} : Point2{0, v}, g1 = x ? Point2{v, 1} : Point2{1, v};
    // sign of t_f - t_g along a->b, times the direction of the coordinate along a->b
    return robust::compare_crossings(ex.a, ex.b, ex.f0, ex.f1, g0, g1) * sgn_diff(b, a) < 0;
  }
  /// The hot pixels of a crossing point rounded to nearest: the exact point is within half an ulp,
  /// so its pixel is that of the rounded point or of a neighbouring double (more hot pixels than
  /// needed is harmless; fewer would not be).
  void add_hot_near(const Point2& p) {
    const double xs[3] = {std::nextafter(p.x, -INFINITY), p.x, std::nextafter(p.x, INFINITY)};
    const double ys[3] = {std::nextafter(p.y, -INFINITY), p.y, std::nextafter(p.y, INFINITY)};
    for (double x : xs)
      for (double y : ys) add_hot(pixel_of({x, y}));
  }

  /// Exact: does segment ab meet the half-open pixel p?
  bool meets(const Point2& a, const Point2& b, const Pix& p) const {
    const double x0 = static_cast<double>(p.i) * g_, x1 = static_cast<double>(p.i + 1) * g_;
    const double y0 = static_cast<double>(p.j) * g_, y1 = static_cast<double>(p.j + 1) * g_;
    if (std::max(a.x, b.x) < x0 || std::min(a.x, b.x) >= x1 || std::max(a.y, b.y) < y0 || std::min(a.y, b.y) >= y1)
      return false;
    return line_meets(a, b, p);
  }
  /// Exact: does the line through a and b meet the half-open pixel p?
  bool line_meets(const Point2& a, const Point2& b, const Pix& p) const {
    const double x0 = static_cast<double>(p.i) * g_, x1 = static_cast<double>(p.i + 1) * g_;
    const double y0 = static_cast<double>(p.j) * g_, y1 = static_cast<double>(p.j + 1) * g_;
    // corners shifted by (-eps, -eps): where a corner is on the line, the side is -sign((b-a) x (1,1))
    const int tie = -cross_sign(a, b, Point2{0, 0}, Point2{1, 1});
    bool pos = false, neg = false;
    const Point2 corners[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    for (const Point2& c : corners) {
      int s = orient(a, b, c);
      if (s == 0) s = tie;
      pos |= s > 0;
      neg |= s < 0;
    }
    return pos && neg;
  }

  /// The hot pixels segment ab meets, ordered along a->b.
  void route(const Point2& a, const Point2& b, std::vector<std::uint32_t>& out) {
    out.clear();
    Box q;
    q.add(a);
    q.add(b);
    q.grow(g_);
    hot_grid_.query(q, [&](std::uint32_t h) {
      if (meets(a, b, hot_[h])) out.push_back(h);
    });
    // along a monotone segment the pixels met form a staircase: sx*i + sy*j increases strictly
    const std::int64_t sx = sgn_diff(b.x, a.x), sy = sgn_diff(b.y, a.y);
    std::sort(out.begin(), out.end(), [&](std::uint32_t u, std::uint32_t v) {
      return sx * hot_[u].i + sy * hot_[u].j < sx * hot_[v].i + sy * hot_[v].j;
    });
  }

  /// The hot pixels met by the segment on the line a->b from a point in pixel P to a point in pixel Q
  /// (both hot), ordered along a->b. Exact for exact points anywhere on the line: along a monotone line
  /// the pixels it meets form a staircase on which sx*i + sy*j increases strictly, and the segment's
  /// pixels are those of the staircase from P to Q.
  void route_on_line(const Point2& a, const Point2& b, const Pix& P, const Pix& Q, std::vector<std::uint32_t>& out) {
    out.clear();
    const std::uint32_t hp = index_.at(P), hq = index_.at(Q);
    out.push_back(hp);
    if (P == Q) return;
    const std::int64_t sx = sgn_diff(b.x, a.x), sy = sgn_diff(b.y, a.y);
    const auto key = [&](const Pix& p) { return sx * p.i + sy * p.j; };
    const std::int64_t kp = key(P), kq = key(Q);
    Box q;
    q.minx = static_cast<double>(std::min(P.i, Q.i)) * g_;
    q.maxx = static_cast<double>(std::max(P.i, Q.i) + 1) * g_;
    q.miny = static_cast<double>(std::min(P.j, Q.j)) * g_;
    q.maxy = static_cast<double>(std::max(P.j, Q.j) + 1) * g_;
    hot_grid_.query(q, [&](std::uint32_t h) {
      const Pix& p = hot_[h];
      if (h == hp || h == hq || p.i < std::min(P.i, Q.i) || p.i > std::max(P.i, Q.i) || p.j < std::min(P.j, Q.j) ||
          p.j > std::max(P.j, Q.j))
        return;
      const std::int64_t k = key(p);
      if (k > kp && k < kq && line_meets(a, b, p)) out.push_back(h);
    });
    out.push_back(hq);
    std::sort(out.begin() + 1, out.end() - 1,
              [&](std::uint32_t u, std::uint32_t v) { return key(hot_[u]) < key(hot_[v]); });
  }

  bool run(const std::vector<RingOut>& walks, std::vector<SnappedRing>& out, SnapStats& stats);

 private:
  struct Seg {
    Point2 a, b;      // the rounded points (ends of the segment as output where kept)
    Point2 la, lb;    // the exact segment lies on the line la->lb, from a point in pixel pa to one in pb
    Pix pa, pb;
    std::uint32_t walk;
    bool exact;       // false: a rounded walk given without its exact vertices (taken as rounded)
  };
  struct GEdge {
    std::uint32_t u, v, walk;
  };
  double g_;
  std::vector<Pix> hot_;
  std::unordered_map<Pix, std::uint32_t, PixHash> index_;
  BoxGrid hot_grid_;
};

bool SnapRounder::run(const std::vector<RingOut>& walks, std::vector<SnappedRing>& out, SnapStats& stats) {
  // 1. segments of the walks; their vertices make hot pixels
  std::vector<Seg> segs;
  std::vector<std::vector<Pix>> vpix(walks.size());  // the exact pixel of every walk vertex
  Box all;
  for (std::uint32_t w = 0; w < walks.size(); ++w) {
    const RingOut& W = walks[w];
    const bool exact = W.exact.size() == W.pts.size();
    const std::size_t n = W.pts.size();
    for (std::size_t k = 0; k < n; ++k) {
      vpix[w].push_back(exact_pixel(W.pts[k], exact ? &W.exact[k] : nullptr));
      add_hot(vpix[w].back());
      all.add(W.pts[k]);
    }
    // the segment ending at vertex k lies on exact[k]'s line (for a walk without them: its own points)
    for (std::size_t k = 0; k < n && n > 1; ++k) {
      const std::size_t k1 = (k + 1) % n;
      if (vpix[w][k] == vpix[w][k1]) continue;  // within one pixel: no grid edge
      const Point2 &a = W.pts[k], &b = W.pts[k1];
      if (exact)
        segs.push_back({a, b, W.exact[k1].a, W.exact[k1].b, vpix[w][k], vpix[w][k1], w, true});
      else
        segs.push_back({a, b, a, b, vpix[w][k], vpix[w][k1], w, !W.rounded});
    }
  }
  if (segs.empty()) return true;
  // 2. crossings of rounded segments make hot pixels (exact orientation; the point correctly rounded): only
  // where a walk is given as rounded points alone; exact walk segments do not cross
  {
    std::vector<Box> boxes(segs.size());
    for (std::size_t s = 0; s < segs.size(); ++s) {
      boxes[s].add(segs[s].a);
      boxes[s].add(segs[s].b);
    }
    BoxGrid sg;
    sg.build(boxes, all, boxes.size());
    for (std::uint32_t s = 0; s < segs.size(); ++s) {
      const Seg& S = segs[s];
      sg.query(boxes[s], [&](std::uint32_t t) {
        if (t <= s || !boxes[s].overlaps(boxes[t]) || (S.exact && segs[t].exact)) return;
        const Seg& T = segs[t];
        const int o1 = orient(S.a, S.b, T.a), o2 = orient(S.a, S.b, T.b);
        if (o1 * o2 >= 0) return;
        const int o3 = orient(T.a, T.b, S.a), o4 = orient(T.a, T.b, S.b);
        if (o3 * o4 >= 0) return;
        add_hot_near(robust::crossing_point(S.a, S.b, T.a, T.b));
      });
    }
  }
  stats.hot_pixels += hot_.size();
  {
    std::vector<Box> pb(hot_.size());
    Box hall;
    for (std::uint32_t h = 0; h < hot_.size(); ++h) {
      pb[h].add(centre(h));
      hall.add(centre(h));
    }
    hot_grid_.build(pb, hall, pb.size());
  }
  // 3. iterated snap rounding: each segment through the centres of the hot pixels it meets, each
  // piece again until no piece meets a hot pixel other than its ends
  std::vector<GEdge> gedges;
  std::vector<std::uint32_t> path, sub;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack;
  std::size_t budget = 64 * segs.size() + 100000;
  for (const Seg& S : segs) {
    route_on_line(S.la, S.lb, S.pa, S.pb, path);
    for (std::size_t k = 0; k + 1 < path.size(); ++k) stack.emplace_back(path[k], path[k + 1]);
    while (!stack.empty()) {
      if (budget-- == 0) return false;
      const auto [u, v] = stack.back();
      stack.pop_back();
      route(centre(u), centre(v), sub);
      if (sub.size() <= 2) {
        gedges.push_back({u, v, S.walk});
        continue;
      }
      for (std::size_t k = 0; k + 1 < sub.size(); ++k) stack.emplace_back(sub[k], sub[k + 1]);
    }
  }
  // 4. cancellation: opposite coincident grid edges are a collapsed sliver (of union or exterior)
  std::sort(gedges.begin(), gedges.end(), [](const GEdge& x, const GEdge& y) {
    const auto kx = std::minmax(x.u, x.v), ky = std::minmax(y.u, y.v);
    return kx < ky || (kx == ky && x.walk < y.walk);
  });
  std::vector<GEdge> kept;
  std::vector<std::vector<std::uint32_t>> kept_walks;
  for (std::size_t i = 0; i < gedges.size();) {
    const auto key = std::minmax(gedges[i].u, gedges[i].v);
    std::size_t j = i;
    int net = 0;
    std::vector<std::uint32_t> ws;
    for (; j < gedges.size() && std::minmax(gedges[j].u, gedges[j].v) == key; ++j) {
      net += gedges[j].u < gedges[j].v ? 1 : -1;
      if (ws.empty() || ws.back() != gedges[j].walk) ws.push_back(gedges[j].walk);
    }
    if (net > 1 || net < -1) return false;  // two faces on one side of an edge: cannot happen
    stats.cancelled += (j - i - static_cast<std::size_t>(net != 0)) / 2;
    if (net != 0) {
      kept.push_back(net > 0 ? GEdge{key.first, key.second, 0} : GEdge{key.second, key.first, 0});
      kept_walks.push_back(std::move(ws));
    }
    i = j;
  }
  // 5. rings: at each vertex the incoming edge continues with the outgoing edge first clockwise
  // from its reverse (the engine's rule: minimal rings, pinches come out in OGC form)
  const std::size_t ne = kept.size();
  std::vector<std::uint32_t> ostart(hot_.size() + 1, 0), outs(ne);
  for (const GEdge& e : kept) ++ostart[e.u + 1];
  for (std::size_t k = 1; k < ostart.size(); ++k) ostart[k] += ostart[k - 1];
  {
    std::vector<std::uint32_t> fill(ostart.begin(), ostart.end() - 1);
    for (std::uint32_t e = 0; e < ne; ++e) outs[fill[kept[e].u]++] = e;
  }
  auto dir = [&](std::uint32_t from, std::uint32_t to) {
    return std::pair<std::int64_t, std::int64_t>{hot_[to].i - hot_[from].i, hot_[to].j - hot_[from].j};
  };
  auto half = [](const std::pair<std::int64_t, std::int64_t>& d) { return d.second > 0 || (d.second == 0 && d.first > 0) ? 0 : 1; };
  auto ccw_less = [&](const std::pair<std::int64_t, std::int64_t>& a, const std::pair<std::int64_t, std::int64_t>& b) {
    const int ha = half(a), hb = half(b);
    if (ha != hb) return ha < hb;
    return static_cast<__int128>(a.first) * b.second - static_cast<__int128>(a.second) * b.first > 0;
  };
  std::vector<std::uint32_t> next(ne), chosen(ne, 0);
  for (std::uint32_t e = 0; e < ne; ++e) {
    const std::uint32_t v = kept[e].v;
    const auto r = dir(v, kept[e].u);
    std::uint32_t best = std::numeric_limits<std::uint32_t>::max(), top = best;
    for (std::uint32_t k = ostart[v]; k < ostart[v + 1]; ++k) {
      const std::uint32_t o = outs[k];
      const auto d = dir(v, kept[o].v);
      if (top == std::numeric_limits<std::uint32_t>::max() || ccw_less(dir(v, kept[top].v), d)) top = o;
      if (ccw_less(d, r) && (best == std::numeric_limits<std::uint32_t>::max() || ccw_less(dir(v, kept[best].v), d)))
        best = o;
    }
    if (best == std::numeric_limits<std::uint32_t>::max()) best = top;
    if (best == std::numeric_limits<std::uint32_t>::max() || chosen[best]++) return false;
    next[e] = best;
  }
  // 6. Exact by default: a hot pixel holding one walk vertex (an input vertex, or a crossing correctly
  // rounded) and nothing else near it (no other hot pixel in its 5x5 neighbourhood, no other grid edge
  // meeting its 3x3 neighbourhood) keeps that vertex instead of its centre. Checked exactly afterwards (no crossing, no vertex within g/2 of an
  // edge it is not on); if that fails, every vertex goes to its centre (plain ISR, valid by construction).
  std::vector<Point2> rep(hot_.size());
  std::vector<std::uint8_t> state(hot_.size(), 0);  // 0 no walk vertex, 1 one walk vertex, 2 more
  for (std::uint32_t wi = 0; wi < walks.size(); ++wi)
    for (std::size_t k = 0; k < walks[wi].pts.size(); ++k) {
      const RingOut& w = walks[wi];
      const std::uint32_t h = index_.at(vpix[wi][k]);
      if (state[h] == 0) {
        state[h] = 1;
        rep[h] = w.pts[k];
      } else if (state[h] == 1 && !(rep[h] == w.pts[k])) {
        state[h] = 2;
      }
    }
  std::vector<char> moved(hot_.size(), 0);
  bool any_moved = false;
  {
    std::vector<Box> eb(ne);
    Box eall;
    for (std::uint32_t e = 0; e < ne; ++e) {
      eb[e].add(centre(kept[e].u));
      eb[e].add(centre(kept[e].v));
      eall.add(centre(kept[e].u));
      eall.add(centre(kept[e].v));
    }
    BoxGrid egrid;
    if (ne) egrid.build(eb, eall, eb.size());
    for (std::uint32_t h = 0; h < hot_.size(); ++h) {
      if (state[h] != 1 || ostart[h + 1] == ostart[h]) continue;
      bool alone = true;
      for (std::int64_t di = -2; di <= 2 && alone; ++di)
        for (std::int64_t dj = -2; dj <= 2 && alone; ++dj)
          if ((di || dj) && index_.count(Pix{hot_[h].i + di, hot_[h].j + dj})) alone = false;
      if (!alone) continue;
      Box n;
      n.minx = static_cast<double>(hot_[h].i - 1) * g_;
      n.maxx = static_cast<double>(hot_[h].i + 2) * g_;
      n.miny = static_cast<double>(hot_[h].j - 1) * g_;
      n.maxy = static_cast<double>(hot_[h].j + 2) * g_;
      egrid.query(n, [&](std::uint32_t e) {
        if (!alone || kept[e].u == h || kept[e].v == h || !n.overlaps(eb[e])) return;
        const Point2 a = centre(kept[e].u), b = centre(kept[e].v);
        const Point2 c[4] = {{n.minx, n.miny}, {n.maxx, n.miny}, {n.maxx, n.maxy}, {n.minx, n.maxy}};
        int pos = 0, neg = 0, zero = 0;
        for (const Point2& q : c) {
          const int o = orient(a, b, q);
          pos += o > 0;
          neg += o < 0;
          zero += o == 0;
        }
        // separating axes: the boxes overlap, so the closed box is met unless its corners are all
        // strictly on one side of the edge's line
        if (zero > 0 || (pos > 0 && neg > 0)) alone = false;
      });
      if (alone) moved[h] = any_moved = 1;
    }
  }
  auto build = [&](bool exact) {
    out.clear();
    std::vector<char> used(ne, 0);
    for (std::uint32_t e0 = 0; e0 < ne; ++e0) {
      if (used[e0]) continue;
      std::vector<Point2> ring;
      std::vector<std::uint32_t> ws;
      for (std::uint32_t e = e0; !used[e]; e = next[e]) {
        used[e] = 1;
        const std::uint32_t u = kept[e].u;
        ring.push_back(exact && moved[u] ? rep[u] : centre(u));
        for (std::uint32_t w : kept_walks[e]) ws.push_back(w);
      }
      std::sort(ws.begin(), ws.end());
      ws.erase(std::unique(ws.begin(), ws.end()), ws.end());
      std::vector<std::uint32_t> polys;
      for (std::uint32_t w : ws) polys.insert(polys.end(), walks[w].polys.begin(), walks[w].polys.end());
      std::sort(polys.begin(), polys.end());
      polys.erase(std::unique(polys.begin(), polys.end()), polys.end());
      std::vector<std::vector<Point2>> parts;
      split_simple(ring, parts);
      for (auto& p : parts) out.push_back(SnappedRing{std::move(p), polys});
    }
  };
  if (any_moved) {
    build(true);
    // exact check of the moved geometry: no two edges cross or overlap, no vertex near an edge it is not on
    bool ok = true;
    {
      std::vector<std::vector<Point2>*> rr;
      for (SnappedRing& r : out) rr.push_back(&r.pts);
      Conflict c{};
      ok = !find_conflict(rr, c);
    }
    for (std::uint32_t e = 0; e < ne && ok; ++e) {
      const std::uint32_t u = kept[e].u, v = kept[e].v;
      if (!moved[u] && !moved[v]) continue;
      const Point2 a = moved[u] ? rep[u] : centre(u), b = moved[v] ? rep[v] : centre(v);
      Box q;
      q.add(a);
      q.add(b);
      q.grow(2 * g_);
      hot_grid_.query(q, [&](std::uint32_t w) {
        if (!ok || w == u || w == v || ostart[w + 1] == ostart[w]) return;
        const Point2 p = moved[w] ? rep[w] : centre(w);
        if (dist_to_segment(p, a, b) <= 0.5L * g_) ok = false;
      });
    }
    if (ok) return true;
    stats.exact_fallbacks += 1;
  }
  build(false);
  return true;
}

}  // namespace

std::vector<std::uint32_t> proximity_groups(const std::vector<RingOut>& walks, double pitch) {
  std::vector<std::uint32_t> parent(walks.size());
  for (std::uint32_t w = 0; w < walks.size(); ++w) parent[w] = w;
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<Box> boxes;
  std::vector<std::uint32_t> owner;
  Box all;
  const double d = 4 * pitch;
  for (std::uint32_t w = 0; w < walks.size(); ++w) {
    const auto& pts = walks[w].pts;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      Box b;
      b.add(pts[k]);
      b.add(pts[(k + 1) % pts.size()]);
      b.grow(d);
      all.add({b.minx, b.miny});
      all.add({b.maxx, b.maxy});
      boxes.push_back(b);
      owner.push_back(w);
    }
  }
  if (boxes.empty()) return parent;
  BoxGrid grid;
  grid.build(boxes, all, boxes.size());
  for (std::uint32_t s = 0; s < boxes.size(); ++s) {
    grid.query(boxes[s], [&](std::uint32_t t) {
      if (owner[t] == owner[s] || !boxes[s].overlaps(boxes[t])) return;
      const std::uint32_t a = find(owner[s]), b = find(owner[t]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    });
  }
  for (std::uint32_t w = 0; w < walks.size(); ++w) parent[w] = find(w);
  return parent;
}

namespace {

/// Whether p lies within d of the interior of segment ab without being exactly on it (exact contact, a
/// T-junction, is how OGC plans touch; the ends are the vertex-vertex test's).
bool near_interior(const Point2& p, const Point2& a, const Point2& b, long double d) {
  if (p == a || p == b || orient(a, b, p) == 0) return false;
  const long double dx = static_cast<long double>(b.x) - a.x, dy = static_cast<long double>(b.y) - a.y;
  const long double px = static_cast<long double>(p.x) - a.x, py = static_cast<long double>(p.y) - a.y;
  const long double l2 = dx * dx + dy * dy;
  const long double t = l2 > 0 ? (px * dx + py * dy) / l2 : 0;
  if (!(t > 0 && t < 1)) return false;
  const long double ex = px - t * dx, ey = py - t * dy;
  return ex * ex + ey * ey <= d * d;
}

}  // namespace

bool clean_as_rounded(const std::vector<std::vector<Point2>>& rings, double pitch, bool near) {
  {
    std::vector<std::vector<Point2>*> rr;
    for (const auto& r : rings) rr.push_back(const_cast<std::vector<Point2>*>(&r));
    Conflict c{};
    if (find_conflict(rr, c)) return false;
    // a hole touching its shell at two points passes find_conflict (rings of one plan may touch) but
    // is invalid (interior disconnected): the 9ec94c3b fuzz regression
    if (touch_cycle(rr)) return false;
  }
  return !near || !near_touching(rings, pitch);
}

bool near_touching(const std::vector<std::vector<Point2>>& rings, double pitch) {
  std::vector<Point2> pts;
  for (const auto& r : rings) pts.insert(pts.end(), r.begin(), r.end());
  if (pts.size() < 2) return false;
  const auto xy = [](const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); };
  std::sort(pts.begin(), pts.end(), xy);
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  const long double d = pitch;
  // vertex-vertex: distinct vertices within a pitch (a sweep by x; of the vertices with the same x only the
  // next in y, so that thousands of vertices on one grid line cost no more than a pass)
  for (std::size_t i = 0, k = 0; i < pts.size(); ++i) {
    if (i + 1 < pts.size() && pts[i + 1].x == pts[i].x && pts[i + 1].y - pts[i].y <= pitch) return true;
    k = std::max(k, i + 1);
    while (k < pts.size() && pts[k].x == pts[i].x) ++k;  // the first vertex right of this x
    for (std::size_t j = k; j < pts.size() && pts[j].x - pts[i].x <= pitch; ++j)
      if (std::fabs(pts[j].y - pts[i].y) <= pitch) return true;
  }
  // vertex-edge: a vertex within a pitch of an edge's interior, not on it
  bool found = false;
  auto edges = [&](auto&& per_edge) {
    for (const auto& r : rings)
      for (std::size_t i = 0, n = r.size(); i < n && !found; ++i) per_edge(r[i], r[(i + 1) % n]);
  };
  if (pts.size() <= 48) {  // small: every pair behind a box test (no grid to build)
    edges([&](const Point2& a, const Point2& b) {
      Box q;
      q.add(a);
      q.add(b);
      q.grow(pitch);
      for (const Point2& p : pts)
        if (q.contains(p) && near_interior(p, a, b, d)) {
          found = true;
          break;
        }
    });
    return found;
  }
  std::vector<Box> pb(pts.size());
  Box all;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    pb[k].add(pts[k]);
    all.add(pts[k]);
  }
  BoxGrid grid;
  grid.build(pb, all, pb.size());
  edges([&](const Point2& a, const Point2& b) {
    Box q;
    q.add(a);
    q.add(b);
    q.grow(pitch);
    grid.query(q, [&](std::uint32_t k) { found = found || (q.contains(pts[k]) && near_interior(pts[k], a, b, d)); });
  });
  return found;
}

bool clean_near_rounded(const std::vector<std::vector<Point2>>& rings, const std::vector<char>& rounded, double pitch) {
  // only rings that can meet a rounded one: the others are exact and pairwise fine
  std::vector<Box> rb;
  Box all;
  std::vector<Box> box(rings.size());
  for (std::size_t i = 0; i < rings.size(); ++i) {
    for (const Point2& p : rings[i]) box[i].add(p);
    box[i].grow(pitch);
    if (rounded[i]) {
      rb.push_back(box[i]);
      all.add({box[i].minx, box[i].miny});
      all.add({box[i].maxx, box[i].maxy});
    }
  }
  if (rb.empty()) return true;
  BoxGrid grid;
  grid.build(rb, all, rb.size());
  std::vector<std::vector<Point2>> sel;
  for (std::size_t i = 0; i < rings.size(); ++i) {
    bool take = rounded[i] != 0;
    if (!take)
      grid.query(box[i], [&](std::uint32_t k) { take = take || box[i].overlaps(rb[k]); });
    if (take) sel.push_back(rings[i]);
  }
  return clean_as_rounded(sel, pitch, false);
}

double snap_pitch(double max_abs) {
  const double m = std::max(std::fabs(max_abs), 0x1p-150);
  const double ulp = std::nextafter(m, INFINITY) - m;
  return 16 * ulp;
}

bool snap_round(const std::vector<RingOut>& walks, double pitch, std::vector<SnappedRing>& out, SnapStats& stats) {
  SnapRounder s(pitch);
  if (s.run(walks, out, stats)) return true;
  out.clear();
  return false;
}

}  // namespace groundplan::detail

// SPDX-License-Identifier: MIT
// --close-gaps (issue 9): the morphological closing of the plans by d = D/2 with mitre joins, built
// from the exact union engine only, then reconciled with the input so that walls stay where they were.
//
// Dilation. The mitre offset of a region by d is the region plus, for every edge, the rectangle swept
// by the edge moved outwards by up to d (a "strip"), plus, at every vertex where the boundary turns
// towards the material (convex), the mitre wedge between the two strips. At reflex vertices the strips
// overlap and need nothing. All of it is handed to build_ground_plans as polygons of one footprint per
// input plan, so the union is exact and the members of a dilated plan name the input plans inside it.
//
// Erosion. The engine only unites, so the erosion of a dilated plan P is taken through its
// complement: inside a rectangle M around P, (M \ P) plus the strips along P's edges pointing into P
// plus the mitre wedges at P's reflex vertices is M \ erosion(P); the erosion is the even-odd region
// of every ring of that union except M's own. Dilated plans are disjoint, so each is eroded on its
// own (tbb::parallel_for over them, one thread per union call).
//
// Mitre limit. Where a mitre would reach farther than kMitreLimit * d from its vertex (turns sharper
// than about 168.5 degrees), it is clipped by a line perpendicular to the bisector at distance
// kMitreLimit * d, ending on the two offset lines (GEOS's "limited mitre" with the same limit; GEOS
// 3.11 places the clip's ends at an approximation of the offset lines, within 0.5 % of d). The value
// keeps the corners of ordinary buildings sharp and bounds the reach of slivers' spikes.
//
// Reconciliation. Offsets and crossings are rounded to doubles twice (dilation, erosion), so the
// closing comes back with its walls a few ulps from the input's. Uniting it with the input as it is
// would leave sliver-shaped vertices along every wall. So the closing's vertices within eps of an input
// vertex move onto it, its other almost-straight vertices (within eps of the chord of their kept
// neighbours) go, and input vertices within eps of its edges are inserted into them; the input plans
// themselves are never moved. Then the input plans and the reconciled closing are united: the result
// contains every input plan exactly, and where the closing adds nothing the input comes back
// vertex for vertex (a dilated plan whose reconciled closing is its input plans is passed through).
#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "lod/ring_geometry.h"
#include "robust/predicates.h"

namespace groundplan {
namespace {

// Mitre length limit as a multiple of d (documented in docs/level_of_detail.md and above).
constexpr double kMitreLimit = 10.0;

struct Vec {
  double x = 0, y = 0;
};

Point2 along(const Point2& p, const Vec& v, double s) { return Point2{p.x + v.x * s, p.y + v.y * s}; }

double ring_area2(const Ring& r) { return static_cast<double>(lod::ring_area2(r)); }


// The ring without consecutive repeated points (the closing vertex included).
Ring without_repeats(const Ring& r) {
  Ring out;
  out.reserve(r.size());
  for (const Point2& p : r)
    if (out.empty() || !(out.back() == p)) out.push_back(p);
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  return out;
}

// The pieces that, united with the ring's region, offset it by d to one side: side = +1 to the right of
// the ring's direction, -1 to the left. Strips along every edge; a join where the ring turns away from
// the offset side (that side is then the outside of the turn). Pieces are appended as polygons.
void add_offset_pieces(const Ring& input, double d, int side, std::vector<Polygon>& out) {
  const Ring r = without_repeats(input);
  const std::size_t n = r.size();
  if (n < 2) return;
  std::vector<Vec> t(n), nrm(n);  // unit direction and unit offset normal of edge i = r[i] -> r[i+1]
  for (std::size_t i = 0; i < n; ++i) {
    const Point2& a = r[i];
    const Point2& b = r[(i + 1) % n];
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double len = std::hypot(dx, dy);
    t[i] = Vec{dx / len, dy / len};
    nrm[i] = Vec{side * t[i].y, -side * t[i].x};
    out.push_back(Polygon{{a, b, along(b, nrm[i], d), along(a, nrm[i], d)}, {}});
  }
  if (n < 3) return;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t e1 = (i + n - 1) % n, e2 = i;  // edges into and out of vertex r[i]
    const Point2& a = r[e1];
    const Point2& b = r[i];
    const Point2& c = r[(i + 1) % n];
    const int turn = robust::orient(a, b, c);
    const Vec& n1 = nrm[e1];
    const Vec& n2 = nrm[e2];
    const double cosine = n1.x * n2.x + n1.y * n2.y;
    const bool reversal = turn == 0 && cosine < 0;  // a zero-width spike: a cap, like the sharpest turn
    if (turn != side && !reversal) continue;
    const Point2 p1 = along(b, n1, d), p2 = along(b, n2, d);
    // |m - b| = d * sqrt(2 / (1 + cos)); within the limit while (1 + cos) * L^2 >= 2.
    if (!reversal && (1 + cosine) * kMitreLimit * kMitreLimit >= 2) {
      const Vec s{n1.x + n2.x, n1.y + n2.y};
      out.push_back(Polygon{{b, p1, along(b, s, d / (1 + cosine)), p2}, {}});
      continue;
    }
    // Clipped mitre. The mitre points along t1 - t2 (parallel to n1 + n2, and well defined however sharp
    // the turn); the clip line is perpendicular to it at distance L d, its ends on the two offset lines.
    const Vec& t1 = t[e1];
    const Vec& t2 = t[e2];
    Vec u{t1.x - t2.x, t1.y - t2.y};
    const double ul = std::hypot(u.x, u.y);
    u = Vec{u.x / ul, u.y / ul};
    const double reach = kMitreLimit * d;
    const double s1 = (reach - d * (n1.x * u.x + n1.y * u.y)) / (t1.x * u.x + t1.y * u.y);
    const double s2 = (reach - d * (n2.x * u.x + n2.y * u.y)) / -(t2.x * u.x + t2.y * u.y);
    out.push_back(Polygon{{b, p1, along(p1, t1, s1), along(p2, t2, -s2), p2}, {}});
  }
}

// Which side of the ring its region lies on: outer rings are counter-clockwise and holes clockwise in
// plans, but the orientation is checked rather than trusted (material on the left iff so).
bool material_left(const Ring& r, bool is_outer) { return (ring_area2(r) > 0) == is_outer; }

// Points on a uniform grid, for "which input vertices lie within eps of this point / segment".
class PointGrid {
 public:
  PointGrid(std::vector<Point2> pts, double eps) : pts_(std::move(pts)), eps_(eps) {
    double x1 = -std::numeric_limits<double>::infinity(), y1 = x1;
    x0_ = y0_ = std::numeric_limits<double>::infinity();
    for (const Point2& p : pts_) {
      x0_ = std::min(x0_, p.x), y0_ = std::min(y0_, p.y);
      x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
    if (pts_.empty()) x0_ = y0_ = x1 = y1 = 0;
    // About one point per cell, never cells finer than a few eps (queries reach eps around).
    const double extent = std::max(x1 - x0_, y1 - y0_);
    const double side = std::ceil(std::sqrt(static_cast<double>(pts_.size()))) + 1;
    h_ = std::max(extent / side, 8 * eps_);
    nx_ = static_cast<int>(std::min(4096.0, std::floor((x1 - x0_) / h_) + 1));
    ny_ = static_cast<int>(std::min(4096.0, std::floor((y1 - y0_) / h_) + 1));
    start_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
    for (const Point2& p : pts_) ++start_[cell(col(p.x), row(p.y)) + 1];
    for (std::size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
    idx_.resize(pts_.size());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::uint32_t i = 0; i < pts_.size(); ++i) idx_[fill[cell(col(pts_[i].x), row(pts_[i].y))]++] = i;
  }

  const Point2& point(std::uint32_t i) const { return pts_[i]; }

  /// The nearest point within eps of p (ties: the lowest index), or -1.
  long nearest(const Point2& p) const {
    long best = -1;
    double best_d2 = eps_ * eps_;
    for (int cx = col(p.x - eps_); cx <= col(p.x + eps_); ++cx)
      for (int cy = row(p.y - eps_); cy <= row(p.y + eps_); ++cy)
        for (std::uint32_t k = start_[cell(cx, cy)]; k < start_[cell(cx, cy) + 1]; ++k) {
          const Point2& q = pts_[idx_[k]];
          const double d2 = (q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y);
          if (d2 < best_d2 || (d2 == best_d2 && best >= 0 && idx_[k] < best)) best = idx_[k], best_d2 = d2;
        }
    return best;
  }

  /// Calls f(i) for every point in a cell that the eps-neighbourhood of segment ab reaches (a superset
  /// of the points within eps of it): column by column, the rows the segment crosses there.
  template <class F>
  void near_segment(const Point2& a, const Point2& b, F&& f) const {
    const double xmin = std::min(a.x, b.x), xmax = std::max(a.x, b.x);
    for (int cx = col(xmin - eps_); cx <= col(xmax + eps_); ++cx) {
      double ylo, yhi;
      if (a.x == b.x) {
        ylo = std::min(a.y, b.y), yhi = std::max(a.y, b.y);
      } else {
        const double xl = std::max(xmin, x0_ + cx * h_ - eps_), xh = std::min(xmax, x0_ + (cx + 1) * h_ + eps_);
        const double ya = a.y + (std::clamp(xl, xmin, xmax) - a.x) * (b.y - a.y) / (b.x - a.x);
        const double yb = a.y + (std::clamp(xh, xmin, xmax) - a.x) * (b.y - a.y) / (b.x - a.x);
        ylo = std::min(ya, yb), yhi = std::max(ya, yb);
        if (cx == 0 || cx == nx_ - 1) ylo = std::min({ylo, a.y, b.y}), yhi = std::max({yhi, a.y, b.y});
      }
      for (int cy = row(ylo - eps_); cy <= row(yhi + eps_); ++cy)
        for (std::uint32_t k = start_[cell(cx, cy)]; k < start_[cell(cx, cy) + 1]; ++k) f(idx_[k]);
    }
  }

 private:
  int col(double x) const { return static_cast<int>(std::clamp(std::floor((x - x0_) / h_), 0.0, nx_ - 1.0)); }
  int row(double y) const { return static_cast<int>(std::clamp(std::floor((y - y0_) / h_), 0.0, ny_ - 1.0)); }
  std::size_t cell(int cx, int cy) const { return static_cast<std::size_t>(cy) * nx_ + cx; }

  std::vector<Point2> pts_;
  double eps_;
  double x0_ = 0, y0_ = 0, h_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::uint32_t> start_, idx_;
};

// Distance from p to segment ab and the parameter of p's projection (unclamped).
std::pair<double, double> segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double vx = b.x - a.x, vy = b.y - a.y, wx = p.x - a.x, wy = p.y - a.y;
  const double l2 = vx * vx + vy * vy;
  const double t = l2 > 0 ? (wx * vx + wy * vy) / l2 : 0;
  const double tc = std::clamp(t, 0.0, 1.0);
  return {std::hypot(wx - tc * vx, wy - tc * vy), t};
}

// The ring without the vertices that lie within tol of the chord between their kept neighbours
// (rounding-scale zigzags and almost-straight vertices), pinned ones excepted; empty when fewer than 3
// remain. Greedy from a kept anchor: a vertex goes when it and every vertex dropped since the anchor
// lie within tol of the chord from the anchor to its successor, so the ring moves by at most tol.
Ring straightened(const Ring& r, const std::vector<char>& pinned, double tol) {
  const std::size_t n = r.size();
  if (n < 3) return {};
  auto is_pinned = [&](std::size_t i) { return !pinned.empty() && pinned[i]; };
  std::size_t start = n;
  for (std::size_t i = 0; i < n && start == n; ++i)
    if (is_pinned(i)) start = i;
  if (start == n) {  // nothing pinned: start at the sharpest corner, which stays
    double worst = -1;
    for (std::size_t i = 0; i < n; ++i) {
      const double dev = segment_distance(r[i], r[(i + n - 1) % n], r[(i + 1) % n]).first;
      if (dev > worst) worst = dev, start = i;
    }
  }
  std::vector<char> keep(n, 1);
  std::size_t anchor = start;
  for (std::size_t s = 1; s < n; ++s) {
    const std::size_t k = (start + s) % n, next = (k + 1) % n;
    bool drop = !is_pinned(k);
    for (std::size_t j = (anchor + 1) % n; drop && j != next; j = (j + 1) % n)
      drop = segment_distance(r[j], r[anchor], r[next]).first <= tol;
    if (drop)
      keep[k] = 0;
    else
      anchor = k;
  }
  Ring kept;
  for (std::size_t s = 0; s < n; ++s)
    if (keep[(start + s) % n]) kept.push_back(r[(start + s) % n]);
  if (kept.size() < 3) return {};
  return kept;
}

// The polygon that is offset: every ring straightened within tol. An edge a few ulps long (where the
// engine rounded two crossings next to each other) has a direction that is noise; its strip and
// its mitre (up to kMitreLimit * d long) would cut a needle into the erosion, which is the exact
// erosion of that zigzag but not of the wall it rounds. Offsetting the straightened rings instead
// moves the result by at most about tol. Empty outer ring when nothing of size tol is left.
Polygon straightened(const Polygon& p, double tol) {
  Polygon out;
  out.outer = straightened(without_repeats(p.outer), {}, tol);
  if (out.outer.empty()) return out;
  for (const Ring& h : p.holes) {
    Ring s = straightened(without_repeats(h), {}, tol);
    if (!s.empty()) out.holes.push_back(std::move(s));
  }
  return out;
}

// One ring of the eroded region, reconciled with the input vertices (see the top of the file).
Ring reconcile_ring(const Ring& ring, const PointGrid& input, double eps) {
  Ring r = ring;
  std::vector<char> pinned(r.size(), 0);  // now exactly an input vertex: never removed
  for (std::size_t i = 0; i < r.size(); ++i) {
    const long k = input.nearest(r[i]);
    if (k >= 0) r[i] = input.point(static_cast<std::uint32_t>(k)), pinned[i] = 1;
  }
  // Drop repeats that snapping made (keeping a pinned copy).
  {
    Ring q;
    std::vector<char> qp;
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (!q.empty() && q.back() == r[i]) {
        qp.back() |= pinned[i];
        continue;
      }
      q.push_back(r[i]), qp.push_back(pinned[i]);
    }
    while (q.size() > 1 && q.front() == q.back()) qp.front() |= qp.back(), q.pop_back(), qp.pop_back();
    r.swap(q), pinned.swap(qp);
  }
  const std::size_t n = r.size();
  if (n < 3) return {};

  const Ring kept = straightened(r, pinned, eps);
  if (kept.empty()) return {};

  // Input vertices within eps of an edge join that edge, in order along it.
  Ring out;
  std::vector<std::pair<double, std::uint32_t>> on_edge;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const Point2& a = kept[i];
    const Point2& b = kept[(i + 1) % kept.size()];
    out.push_back(a);
    on_edge.clear();
    input.near_segment(a, b, [&](std::uint32_t k) {
      const Point2& v = input.point(k);
      if (v == a || v == b) return;
      const auto [dist, t] = segment_distance(v, a, b);
      if (dist <= eps && t > 0 && t < 1) on_edge.emplace_back(t, k);
    });
    std::sort(on_edge.begin(), on_edge.end());
    for (const auto& [t, k] : on_edge)
      if (!(out.back() == input.point(k))) out.push_back(input.point(k));
  }
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  if (out.size() < 3) return {};
  return out;
}

// A ring as a comparable key: positively oriented, starting at its smallest vertex (x, then y).
// Empty when the smallest vertex repeats (a ring touching itself): then it matches nothing.
Ring canonical(const Ring& r) {
  if (r.size() < 3) return {};
  Ring c = r;
  if (ring_area2(c) < 0) std::reverse(c.begin(), c.end());
  auto less = [](const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); };
  const auto m = std::min_element(c.begin(), c.end(), less);
  if (std::count(c.begin(), c.end(), *m) != 1) return {};
  std::rotate(c.begin(), m, c.end());
  return c;
}

bool same_rings(std::vector<Ring> a, std::vector<Ring> b) {
  if (a.size() != b.size()) return false;
  auto key = [](const Ring& r) { return canonical(r); };
  std::vector<Ring> ka, kb;
  for (const Ring& r : a) {
    ka.push_back(key(r));
    if (ka.back().empty()) return false;
  }
  for (const Ring& r : b) {
    kb.push_back(key(r));
    if (kb.back().empty()) return false;
  }
  auto lex = [](const Ring& x, const Ring& y) {
    return std::lexicographical_compare(x.begin(), x.end(), y.begin(), y.end(), [](const Point2& p, const Point2& q) {
      return p.x < q.x || (p.x == q.x && p.y < q.y);
    });
  };
  std::sort(ka.begin(), ka.end(), lex);
  std::sort(kb.begin(), kb.end(), lex);
  return ka == kb;
}

struct GroupResult {
  std::vector<GroundPlan> plans;
  std::vector<std::uint32_t> first_input;  // per plan: the lowest input plan index inside (output order)
  bool failed = false;                     // a union failed: the input plans, unclosed
};

/// The engine reports a block it could not unite as a UNION_FAILED problem (never expected: every
/// decision is exact). Inside the closing that would silently lose pieces, so it becomes an Error
/// here and the group falls back to its input plans.
void throw_if_failed(const std::vector<Problem>& problems, const char* what) {
  for (const Problem& p : problems)
    if (p.code == "UNION_FAILED") throw Error(std::string("close-gaps: the union of the ") + what + " failed: " + p.reason);
}

std::vector<std::uint32_t> merged_members(const std::vector<GroundPlan>& plans, const std::vector<std::uint32_t>& which) {
  std::vector<std::uint32_t> m;
  for (std::uint32_t i : which) m.insert(m.end(), plans[i].members.begin(), plans[i].members.end());
  std::sort(m.begin(), m.end());
  m.erase(std::unique(m.begin(), m.end()), m.end());
  return m;
}

// Erosion of one dilated plan, reconciliation with the input plans inside it, and their union.
GroupResult close_group(const std::vector<GroundPlan>& plans, const GroundPlan& dilated, double d, double eps) {
  const std::vector<std::uint32_t>& group = dilated.members;  // input plan indices, ascending
  UnionParams one_thread;
  one_thread.device = Device::Cpu;  // small unions: the raster backend's start-up would dominate on a GPU
  one_thread.threads = 1;
  std::vector<Problem> ignored;  // a footprint of ours without area is a piece we do not need

  // M \ erosion(P): the complement of P inside M, the inward strips and the joins at reflex vertices.
  const Polygon P = straightened(dilated.polygon, eps);  // at least 2d across: never empty
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const Point2& p : P.outer) x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  x0 -= 2 * d, y0 -= 2 * d, x1 += 2 * d, y1 += 2 * d;
  Footprint cut;
  Polygon complement;
  complement.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  complement.holes.push_back(P.outer);
  complement.holes.insert(complement.holes.end(), P.holes.begin(), P.holes.end());
  cut.polygons.push_back(std::move(complement));
  add_offset_pieces(P.outer, d, material_left(P.outer, true) ? -1 : +1, cut.polygons);
  for (const Ring& h : P.holes) add_offset_pieces(h, d, material_left(h, false) ? -1 : +1, cut.polygons);
  const std::vector<GroundPlan> outside = build_ground_plans({cut}, one_thread, ignored);
  throw_if_failed(ignored, "erosion");

  // The eroded region: every ring but M's (M's plan is the one reaching x0), reconciled.
  std::vector<Point2> input_vertices;
  std::vector<Ring> input_rings;
  for (std::uint32_t i : group) {
    const Polygon& p = plans[i].polygon;
    input_rings.push_back(p.outer);
    input_rings.insert(input_rings.end(), p.holes.begin(), p.holes.end());
  }
  for (const Ring& r : input_rings) input_vertices.insert(input_vertices.end(), r.begin(), r.end());
  const PointGrid grid(std::move(input_vertices), eps);
  std::vector<Ring> eroded;
  auto take = [&](const Ring& r) {
    Ring q = reconcile_ring(r, grid, eps);
    if (!q.empty()) eroded.push_back(std::move(q));
  };
  for (const GroundPlan& g : outside) {
    const bool is_m = std::any_of(g.polygon.outer.begin(), g.polygon.outer.end(), [&](const Point2& p) { return p.x == x0; });
    if (!is_m) take(g.polygon.outer);
    for (const Ring& h : g.polygon.holes) take(h);
  }

  GroupResult out;
  if (same_rings(eroded, input_rings)) {  // the closing adds nothing here: the input, untouched
    for (std::uint32_t i : group) out.plans.push_back(plans[i]), out.first_input.push_back(i);
    return out;
  }

  // The input plans, unmoved, united with the reconciled closing (one even-odd polygon).
  std::vector<Footprint> fps;
  for (std::uint32_t i : group) fps.push_back(Footprint{{plans[i].polygon}, {}, {}, {}, 0, 0, {}});
  if (!eroded.empty()) {
    Polygon e;
    e.outer = std::move(eroded.front());
    e.holes.assign(std::make_move_iterator(eroded.begin() + 1), std::make_move_iterator(eroded.end()));
    fps.push_back(Footprint{{std::move(e)}, {}, {}, {}, 0, 0, {}});
  }
  std::vector<GroundPlan> united = build_ground_plans(fps, one_thread, ignored);
  throw_if_failed(ignored, "closing with its input");
  std::vector<char> placed(group.size(), 0);
  for (GroundPlan& g : united) {
    std::vector<std::uint32_t> inside;
    for (std::uint32_t m : g.members)
      if (m < group.size()) inside.push_back(group[m]), placed[m] = 1;
    if (inside.empty()) continue;  // a rounding-scale piece of the closing alone: it covers no input plan
    g.members = merged_members(plans, inside);
    out.first_input.push_back(inside.front());
    out.plans.push_back(std::move(g));
  }
  // An input plan the engine found no area in (degenerate input) keeps its buildings in the first plan.
  for (std::size_t m = 0; m < group.size(); ++m)
    if (!placed[m] && !out.plans.empty()) {
      std::vector<std::uint32_t>& mem = out.plans.front().members;
      mem.insert(mem.end(), plans[group[m]].members.begin(), plans[group[m]].members.end());
      std::sort(mem.begin(), mem.end());
      mem.erase(std::unique(mem.begin(), mem.end()), mem.end());
    }
  return out;
}

}  // namespace

std::vector<GroundPlan> close_gaps(const std::vector<GroundPlan>& plans, double width_m, const UnionParams& union_params,
                                   LodStats* stats) {
  if (!std::isfinite(width_m) || width_m <= 0)
    throw InvalidArgument("close_gaps: the width must be a positive number of metres, got " + std::to_string(width_m));
  const auto t0 = std::chrono::steady_clock::now();
  const double d = width_m / 2;

  // eps: how far apart the closing's walls may come back from the input's and still be the same
  // wall. The closing passes through two roundings of offsets and crossings (each within a few ulps of
  // the largest coordinate; a corner of angle a amplifies by 1/sin a), so 64 ulps covers corners down
  // to ~2 degrees; 1e-7 m keeps it meaningful near the origin; 1e-5 D ties it to the scale the caller
  // asked for (1 um for D = 10 cm), far below any feature the closing is meant to keep.
  double coord = 0;
  for (const GroundPlan& g : plans) {
    for (const Point2& p : g.polygon.outer) coord = std::max({coord, std::abs(p.x), std::abs(p.y)});
  }
  const double ulp = std::nextafter(coord + width_m, std::numeric_limits<double>::infinity()) - (coord + width_m);
  const double eps = std::max({1e-7, 64 * ulp, 1e-5 * width_m});

  // A convex plan without holes that nothing comes near is its own closing (the mitre offsets of a
  // convex polygon out and back in give it back; a clipped mitre reaches less than (L + 1) d): it
  // passes through untouched and takes no part in the unions. Isolation: boxes grown by that reach,
  // swept along x.
  const double reach = (kMitreLimit + 1) * d;
  std::vector<std::array<double, 4>> box(plans.size());
  for (std::size_t i = 0; i < plans.size(); ++i) {
    auto& b = box[i];
    b = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
         -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (const Point2& p : plans[i].polygon.outer)
      b = {std::min(b[0], p.x - reach), std::min(b[1], p.y - reach), std::max(b[2], p.x + reach), std::max(b[3], p.y + reach)};
  }
  std::vector<char> near(plans.size(), 0);
  {
    std::vector<std::size_t> by_x(plans.size());
    for (std::size_t i = 0; i < by_x.size(); ++i) by_x[i] = i;
    std::sort(by_x.begin(), by_x.end(), [&](std::size_t a, std::size_t b) { return box[a][0] < box[b][0]; });
    for (std::size_t a = 0; a < by_x.size(); ++a)
      for (std::size_t b = a + 1; b < by_x.size() && box[by_x[b]][0] <= box[by_x[a]][2]; ++b) {
        const auto &p = box[by_x[a]], &q = box[by_x[b]];
        if (p[1] <= q[3] && q[1] <= p[3]) near[by_x[a]] = near[by_x[b]] = 1;
      }
  }
  auto convex = [](const Polygon& p) {
    if (!p.holes.empty()) return false;
    const Ring r = without_repeats(p.outer);
    const int side = material_left(r, true) ? +1 : -1;
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Point2 &a = r[(i + r.size() - 1) % r.size()], &b = r[i], &c = r[(i + 1) % r.size()];
      const int turn = robust::orient(a, b, c);
      if (turn == -side || (turn == 0 && (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y) < 0)) return false;
    }
    return r.size() >= 3;
  };

  // Dilation: one footprint per remaining plan, the plan with its outward strips and convex joins.
  std::vector<std::pair<std::uint32_t, GroundPlan>> tagged;  // (first input plan inside, plan)
  std::vector<Footprint> grown;
  std::vector<std::uint32_t> grown_plan;  // footprint -> input plan
  for (std::size_t i = 0; i < plans.size(); ++i) {
    if (!near[i] && convex(plans[i].polygon)) {
      tagged.emplace_back(static_cast<std::uint32_t>(i), plans[i]);
      continue;
    }
    grown_plan.push_back(static_cast<std::uint32_t>(i));
    Footprint& f = grown.emplace_back();
    const Polygon p = straightened(plans[i].polygon, eps);
    if (p.outer.empty()) {  // nothing of size eps: the plan itself, nothing to offset
      f.polygons.push_back(plans[i].polygon);
      continue;
    }
    f.polygons.push_back(p);
    add_offset_pieces(p.outer, d, material_left(p.outer, true) ? +1 : -1, f.polygons);
    for (const Ring& h : p.holes) add_offset_pieces(h, d, material_left(h, false) ? +1 : -1, f.polygons);
  }
  UnionParams dilate_params = union_params;
  dilate_params.stats = nullptr;
  std::vector<Problem> ignored;
  std::vector<GroundPlan> dilated = build_ground_plans(grown, dilate_params, ignored);
  grown.clear();
  grown.shrink_to_fit();
  for (GroundPlan& g : dilated)
    for (std::uint32_t& m : g.members) m = grown_plan[m];  // ascending still: grown_plan is
  std::size_t failed = 0;
  {
    // A block of the dilation that failed (UNION_FAILED) left its input plans in no dilated plan:
    // they pass through unclosed, counted, rather than being lost.
    std::vector<char> in_dilated(plans.size(), 0);
    for (const GroundPlan& g : dilated)
      for (std::uint32_t m : g.members) in_dilated[m] = 1;
    for (std::uint32_t i : grown_plan)
      if (!in_dilated[i]) {
        tagged.emplace_back(i, plans[i]);
        ++failed;
      }
  }

  // Erode and reconcile each dilated plan on its own, the largest first.
  std::vector<GroupResult> results(dilated.size());
  std::vector<std::size_t> order(dilated.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return dilated[a].polygon.outer.size() > dilated[b].polygon.outer.size();
  });
  auto one = [&](std::size_t oi) {
    const GroundPlan& g = dilated[order[oi]];
    try {
      results[order[oi]] = close_group(plans, g, d, eps);
    } catch (const Error&) {
      GroupResult r;
      r.failed = true;
      for (std::uint32_t i : g.members) r.plans.push_back(plans[i]), r.first_input.push_back(i);
      results[order[oi]] = std::move(r);
    }
  };
  const int threads = union_params.threads > 0 ? union_params.threads : tbb::this_task_arena::max_concurrency();
  if (threads == 1 || dilated.size() <= 1) {
    for (std::size_t oi = 0; oi < order.size(); ++oi) one(oi);
  } else {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 1),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t oi = r.begin(); oi != r.end(); ++oi) one(oi);
                        });
    });
  }

  // Output in the order of the input plans (by the first input plan each result contains).
  for (GroupResult& r : results) {
    failed += r.failed ? r.plans.size() : 0;
    for (std::size_t j = 0; j < r.plans.size(); ++j) tagged.emplace_back(r.first_input[j], std::move(r.plans[j]));
  }
  std::stable_sort(tagged.begin(), tagged.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<GroundPlan> out;
  out.reserve(tagged.size());
  for (auto& [first, g] : tagged) out.push_back(std::move(g));

  if (stats) {
    double before = 0, after = 0;
    for (const GroundPlan& g : plans) before += polygon_area(g.polygon);
    for (const GroundPlan& g : out) after += polygon_area(g.polygon);
    stats->close_plans_before = plans.size();
    stats->close_plans_after = out.size();
    stats->close_area_added_m2 = after - before;
    stats->close_plans_failed = failed;
    stats->close_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return out;
}

}  // namespace groundplan

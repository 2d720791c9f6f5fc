// SPDX-License-Identifier: MIT
// Online boundary evaluation (paper §6) for one block, and the exact completeness check (§3, issue 3).
//
// Semantics. Each input polygon (outer ring + holes) covers the points of odd crossing parity over
// all its rings: the even-odd rule. For valid polygons that is the polygon; for bow-ties, holes
// sticking out of the shell, repeated points and zero-area spikes it is what GEOS MakeValid (the
// "linework" method used by the reference in gis/geosref) returns. The ground plan is the union of
// these regions. Edge orientation is therefore never used: crossing an edge of polygon p toggles
// p's parity, and a point is in the union when at least one polygon has odd parity.
//
// The walk (§6.2). Invariant: we move along a boundary piece of the union with the union's
// interior on the left and its exterior on the right (outer rings come out counter-clockwise,
// holes clockwise). Along the current edge the nearest event x0 (Lemma 1) is found among: input
// vertices on the edge (exact), proper crossings with other edges (visibility bisection, §6.3,
// robust/predicates). At x0 every edge through x0 contributes rays; sweeping counter-clockwise
// from the ray pointing back along the incoming edge starts in the exterior wedge (invariant,
// every parity 0), so the parity of every wedge around x0 is known exactly. The outgoing direction
// is a group of coincident rays with the exterior just clockwise of it and the union just
// counter-clockwise; where the boundary touches itself at x0 there are several, and we take the
// one nearest clockwise to the incoming edge, i.e. we turn around the face of the union we are
// walking (see choose_outgoing: the paper's "largest right turn" seen from the interior side, which
// links rings as GEOS does). Coincident rays (collinear overlaps, party walls, duplicates) are one
// group; a polygon toggled twice by a group (a zero-area spike) does not change. Only edges meeting
// the walked edges are ever intersected: no arrangement is built.
//
// Completeness, exactly (the raster only finds blocks; exactness never depends on pixels). Every
// point of the union's boundary lies on an input edge, and a boundary ring is traced entirely as
// soon as one of its pieces is walked. So the union is complete iff every piece of every input edge
// that lies on the boundary has been walked. The check proves this edge by edge:
//   * an edge whose walked pieces chain from one endpoint to the other is done;
//   * otherwise its pieces (between consecutive events) are enumerated exactly, and the parity of
//     every polygon on the left and on the right of the edge is computed: at the start vertex by
//     an exact ray cast (symbolically perturbed into the wedge just above the +x ray) followed by
//     the same angular sweep as the walk, then updated at each event by the rays leaving to each
//     side. A piece with the union on exactly one side is a boundary piece; if it has not been
//     walked, a new walk starts there (a hole, or an outer ring of a part of the block that does
//     not touch the rest), with the exterior on the right.
// Nothing is sampled, so a hole or island far below the pixel size is found like any other. The
// cost is paid only on edges that are not entirely walked (party walls, overlaps, interior edges);
// for separate buildings every edge is walked by the first seed and the check is a lookup.
//
// Output in doubles (assemble: ring_builder.cpp, snap_round.cpp). Input vertices are exact; crossing
// points are rounded. A block whose walks have no crossing point is output exactly; otherwise its
// boundary is snap-rounded on the call's grid (snap_round.h), valid and disjoint by construction.
#include "union/block_union.h"
#include "union/block_types.h"
#include "union/box_grid.h"
#include "union/output_rounding.h"
#include "union/ring_builder.h"

#include <groundplan/error.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>

#include "robust/predicates.h"

namespace groundplan::detail {
namespace {

using robust::cross_sign;
using robust::orient;

/// A point on the current line: an input vertex, or the proper crossing with edge f. Crossing
/// events stay valid on every line collinear with the one they were found on.
struct Event {
  bool cross = false;
  Point2 v;
  std::uint32_t f = 0;
};

/// A ray leaving a point along an input edge, pointing from `from` towards `to` (the edge's
/// endpoints, so directions are exact differences of input doubles).
struct Ray {
  Point2 from, to;
  std::uint32_t edge;
  std::uint32_t poly;
};

/// The set of polygons with odd parity in some wedge: usually 0-3 entries, kept inline (no heap
/// allocation unless more than kInline polygons overlap at one point).
struct Parity {
  static constexpr std::size_t kInline = 6;
  std::uint32_t small[kInline];
  std::size_t n = 0;
  std::vector<std::uint32_t> more;  // used only when n would exceed kInline
  void toggle(std::uint32_t p) {
    if (!more.empty() || n == kInline) {
      if (more.empty()) more.assign(small, small + n);
      auto it = std::find(more.begin(), more.end(), p);
      if (it == more.end()) {
        more.push_back(p);
      } else {
        *it = more.back();
        more.pop_back();
      }
      n = more.size();
      if (n < kInline) {
        std::copy(more.begin(), more.end(), small);
        more.clear();
      }
      return;
    }
    for (std::size_t i = 0; i < n; ++i)
      if (small[i] == p) {
        small[i] = small[--n];
        return;
      }
    small[n++] = p;
  }
  bool inside() const { return n > 0; }
  template <class F>
  void for_each(F&& f) const {
    if (!more.empty()) {
      for (std::uint32_t p : more) f(p);
    } else {
      for (std::size_t i = 0; i < n; ++i) f(small[i]);
    }
  }
};

/// The directed line of the current edge with its exact order of events.
struct Line {
  std::uint32_t e;
  Point2 a, b;
  bool xdom;
  int dir;  // sign of the dominant coordinate's change from a to b

  Line(std::uint32_t edge, const Point2& from, const Point2& to) : e(edge), a(from), b(to) {
    xdom = std::fabs(to.x - from.x) >= std::fabs(to.y - from.y);
    dir = xdom ? sgn_diff(to.x, from.x) : sgn_diff(to.y, from.y);
  }
  double key(const Point2& p) const { return xdom ? p.x : p.y; }
  /// For points on the line: order along a->b.
  int cmp_vv(const Point2& p, const Point2& q) const { return dir * sgn_diff(key(p), key(q)); }
  bool within(const Point2& p) const { return cmp_vv(p, a) >= 0 && cmp_vv(p, b) <= 0; }
};

struct Cand {
  enum Kind : std::uint8_t { Crossing, Touch0, Touch1, PassA, PassB, Collinear };
  std::uint32_t edge;
  Kind kind;
};

struct Piece {
  Event s, t;  // ordered along the edge's own direction p0 -> p1
  std::uint32_t next;  // next piece of the same edge, or kNone
};
constexpr std::uint32_t kNone = 0xffffffffu;

/// How edge f meets the segment of L: one of the candidate kinds, or false where they do not meet.
bool meets(const Line& L, const Edge& f, Cand::Kind& kind) {
  const int o0 = orient(L.a, L.b, f.p0), o1 = orient(L.a, L.b, f.p1);
  if (o0 == 0 && o1 == 0) {
    // collinear: overlap of the extents along the line
    const Point2& lo = L.cmp_vv(f.p0, f.p1) <= 0 ? f.p0 : f.p1;
    const Point2& hi = L.cmp_vv(f.p0, f.p1) <= 0 ? f.p1 : f.p0;
    kind = Cand::Collinear;
    return L.cmp_vv(hi, L.a) >= 0 && L.cmp_vv(lo, L.b) <= 0;
  }
  if (o0 == 0) {
    kind = Cand::Touch0;
    return L.within(f.p0);
  }
  if (o1 == 0) {
    kind = Cand::Touch1;
    return L.within(f.p1);
  }
  if (o0 == o1) return false;
  const int pa = orient(f.p0, f.p1, L.a), pb = orient(f.p0, f.p1, L.b);
  kind = pa == 0 ? Cand::PassA : pb == 0 ? Cand::PassB : Cand::Crossing;
  return pa == 0 || pb == 0 || pa != pb;
}

class BlockEngine {
 public:
  BlockEngine() = default;
  /// Prepares for one block, keeping the capacity of every buffer (one engine per thread).
  void reset(const std::vector<Footprint>& footprints, const std::vector<std::uint32_t>& members, double pitch,
             bool shortcut) {
    pitch_ = pitch;
    shortcut_ = shortcut;
    footprints_ = &footprints;
    members_ = &members;
    edges_.clear();
    polys_.clear();
    ring_first_.clear();
    edge_ring_.clear();
    poly_grid_built_ = false;
    pieces_.clear();
    first_piece_.clear();
    rings_.clear();
    stats_ = BlockStats{};
    step_limit_ = 0;
  }

  BlockResult run();

 private:
  // --- setup
  void load();
  // --- the shortcut: a block whose rings neither touch nor cross one another or themselves
  std::size_t mark_simple_rings();
  void take_ring(std::uint32_t e, bool from_seed);
  void walk_ring(std::uint32_t e, bool forward);
  // --- exact event order on a line
  int cmp(const Line& L, const Event& x, const Event& y) const;
  void scan(const Line& L, std::vector<Cand>& out);
  void build_near_lists(const std::vector<Box>& boxes);
  Event event_of(const Line& L, const Cand& c, int which) const;
  void rays_at(const Line& L, const Event& x, const std::vector<Cand>& cands, std::vector<Ray>& out) const;
  // --- angular order around a point, relative to a reference direction
  void sort_rays(const Point2& r0, const Point2& r1, std::vector<Ray>& rays) const;
  int ray_class(const Point2& r0, const Point2& r1, const Ray& d) const;
  bool same_group(const Point2& r0, const Point2& r1, const Ray& x, const Ray& y) const;
  // --- the walk
  bool choose_outgoing(const Point2& r0, const Point2& r1, std::vector<Ray>& rays, std::size_t& g0,
                       std::size_t& g1, Parity state) const;
  void walk(Line L, Event start, std::vector<Ray> group);
  void mark(const std::vector<Ray>& group, const Line& L, const Event& s, const Event& t);
  Point2 point_of(const Line& L, const Event& x) const;
  // --- completeness
  bool fully_walked(std::uint32_t e);
  bool walked(std::uint32_t e, const Line& L, const Event& s, const Event& t) const;
  void check_edge(std::uint32_t e);
  Parity parity_at_vertex_wedge0(const Point2& p);
  // --- output
  void assemble(BlockResult& out) { assemble_block(rings_, polys_, edges_, pitch_, stats_, out); }

  const std::vector<Footprint>* footprints_ = nullptr;
  const std::vector<std::uint32_t>* members_ = nullptr;
  std::vector<Box> eboxes_, pboxes_;
  std::vector<Edge> edges_;
  std::vector<Poly> polys_;
  std::vector<std::uint32_t> ring_first_;  // first edge of each ring, then edges_.size()
  std::vector<std::uint32_t> edge_ring_;   // the ring of each edge
  std::vector<std::uint32_t> sr_order_, sr_comp_;  // mark_simple_rings(): scratch
  std::vector<std::uint8_t> sr_bad_;
  std::vector<Box> sr_rbox_;
  bool poly_grid_built_ = false;  // in this block
  std::vector<std::uint8_t> ring_simple_;  // per ring: in a component of rings apart (mark_simple_rings)
  std::vector<std::uint8_t> ring_done_;    // per such ring: taken (or covered)
  std::vector<signed char> sr_side_;       // per such ring: +1 union on the left of its edges, -1 right, 0 covered
  std::vector<Point2> sr_pts_;
  Box all_;
  BoxGrid poly_grid_;
  // Broad phase, once per block: for each edge, the edges whose closed boxes meet its box (CSR).
  // Every scan runs along one whole input edge, so this list is all it needs.
  std::vector<std::uint32_t> near_start_, near_items_, sweep_order_, sweep_active_;
  std::vector<Piece> pieces_;               // walked pieces, one list per edge (no per-edge allocation)
  std::vector<std::uint32_t> first_piece_;  // head of each edge's list, or kNone
  std::vector<Piece> chain_scratch_;
  std::vector<std::uint8_t> checked_;
  std::vector<std::uint32_t> check_order_;  // edges proven by the check of an exact twin
  std::vector<RingOut> rings_;
  std::vector<Cand> scratch_cands_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pair_scratch_;
  std::vector<Point2> load_ring_;
  mutable std::vector<std::pair<int, Ray>> sort_scratch_;
  std::vector<Ray> walk_rays_;
  std::vector<ExactVertex> walk_exact_;  // what each vertex of the current walk is; kept if it is rounded
  std::vector<robust::Segment> walk_segs_;
  std::vector<std::uint32_t> walk_seg_edges_, poly_hits_;
  std::vector<Cand> chk_cands_, chk_wcands_;
  std::vector<Event> chk_evs_;
  std::vector<std::pair<std::size_t, std::uint32_t>> chk_at_;
  std::vector<Ray> chk_rays_, chk_wrays_;
  BlockStats stats_;
  std::size_t step_limit_ = 0;
  double pitch_ = 0;
  bool shortcut_ = true;
};

// ------------------------------------------------------------------------------------------------
void BlockEngine::load() {
  std::vector<Box>& eboxes = eboxes_;
  std::vector<Box>& pboxes = pboxes_;
  eboxes.clear();
  pboxes.clear();
  Box all;
  std::vector<Point2>& ring = load_ring_;
  for (std::uint32_t fi : *members_) {
    for (const Polygon& poly : (*footprints_)[fi].polygons) {
      Poly P{fi, static_cast<std::uint32_t>(edges_.size()), 0, Box{}, false};
      const auto pid = static_cast<std::uint32_t>(polys_.size());
      auto add_ring = [&](const Ring& r) {
        ring.clear();
        for (const Point2& p : r) {
          if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
          if (ring.empty() || !(ring.back() == p)) ring.push_back(p);
        }
        while (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
        if (ring.size() < 3) return;  // no area under the even-odd rule
        ring_first_.push_back(static_cast<std::uint32_t>(edges_.size()));
        edge_ring_.insert(edge_ring_.end(), ring.size(), static_cast<std::uint32_t>(ring_first_.size() - 1));
        for (std::size_t i = 0; i < ring.size(); ++i) {
          const Point2& a = ring[i];
          const Point2& b = ring[(i + 1) % ring.size()];
          edges_.push_back(Edge{a, b, pid});
          Box eb;
          eb.add(a);
          eb.add(b);
          eboxes.push_back(eb);
          P.box.add(a);
          if (!P.has_area && i >= 2 && orient(ring[0], ring[1], a) != 0) P.has_area = true;
        }
        if (!P.has_area) {
          for (std::size_t i = 2; i < ring.size() && !P.has_area; ++i)
            if (orient(ring[0], ring[1], ring[i]) != 0) P.has_area = true;
        }
      };
      add_ring(poly.outer);
      for (const Ring& h : poly.holes) add_ring(h);
      P.end_edge = static_cast<std::uint32_t>(edges_.size());
      if (P.end_edge == P.first_edge) continue;
      polys_.push_back(P);
      pboxes.push_back(P.box);
      all.minx = std::min(all.minx, P.box.minx);
      all.miny = std::min(all.miny, P.box.miny);
      all.maxx = std::max(all.maxx, P.box.maxx);
      all.maxy = std::max(all.maxy, P.box.maxy);
    }
  }
  ring_first_.push_back(static_cast<std::uint32_t>(edges_.size()));
  all_ = all;
  if (edges_.empty()) return;
  build_near_lists(eboxes);
  first_piece_.assign(edges_.size(), kNone);
  checked_.assign(edges_.size(), 0);
  pieces_.reserve(edges_.size() + 16);
  // A safety net against a walk that never closes (a bug), not a limit on real input: a ring has
  // at most one step per piece of the block's arrangement, O(E^2) in the worst case.
  step_limit_ = std::min<std::size_t>(edges_.size() * edges_.size() * 4 + 4096, std::size_t{1} << 40);
}

// ------------------------------------------------------------------------------------------------
// The shortcut (most blocks are one detached building, and a block the raster made of several buildings is
// mostly buildings apart). Polygons whose closed boxes meet, transitively, make a component; only edges of one
// component can meet, and only its polygons can cover its points. Where in a component no edge meets any edge but
// its two neighbours in its ring, and those only at their common vertex (turning, or going straight on), every ring
// is simple and no two rings meet. Then a ring is a boundary of the union unless another polygon of the component
// covers it (the even-odd parity of each polygon is the same all along it), and the walk of a boundary ring is the
// ring itself, in the direction with the union on the left (its own polygon's parity just inside it, from its
// orientation and how many of its polygon's rings contain it). run() takes such rings as walks in the order, from
// the start points and in the directions the walk and the completeness check would (so the plans are the same bit
// for bit): the ring of the rightmost (then topmost) vertex counter-clockwise from that vertex; then, edges longest
// first, the ring of the first edge not walked yet, from that edge's start. Other components are walked as before.
// Returns the number of rings so handled (ring_simple_); their sides in sr_side_ (0: covered, no walk).
std::size_t BlockEngine::mark_simple_rings() {
  const auto np = static_cast<std::uint32_t>(polys_.size());
  const std::size_t nr = ring_first_.size() - 1;
  // components of polygons by their closed boxes: sweep over x, union-find
  std::vector<std::uint32_t>& order = sr_order_;
  std::vector<std::uint32_t>& comp = sr_comp_;
  order.resize(np);
  comp.resize(np);
  std::iota(order.begin(), order.end(), 0u);
  std::iota(comp.begin(), comp.end(), 0u);
  auto find = [&](std::uint32_t a) {
    while (comp[a] != a) a = comp[a] = comp[comp[a]];
    return a;
  };
  if (np > 1) {
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return polys_[a].box.minx < polys_[b].box.minx; });
    for (std::size_t i = 0; i < np; ++i)
      for (std::size_t j = i + 1; j < np && polys_[order[j]].box.minx <= polys_[order[i]].box.maxx; ++j)
        if (polys_[order[i]].box.overlaps(polys_[order[j]].box)) comp[find(order[i])] = find(order[j]);
  }
  for (std::uint32_t p = 0; p < np; ++p) comp[p] = find(p);
  std::vector<std::uint8_t>& bad = sr_bad_;  // per component root: some edges meet
  bad.assign(np, 0);
  const auto ne = static_cast<std::uint32_t>(edges_.size());
  auto next_of = [&](std::uint32_t e) { return e + 1 == ring_first_[edge_ring_[e] + 1] ? ring_first_[edge_ring_[e]] : e + 1; };
  auto prev_of = [&](std::uint32_t e) { return e == ring_first_[edge_ring_[e]] ? ring_first_[edge_ring_[e] + 1] - 1 : e - 1; };
  // Every pair of edges whose boxes meet, once (the near lists hold both ways), decided as scan() does.
  auto meet = [&](std::uint32_t e, std::uint32_t fi) {
    const Line L(e, edges_[e].p0, edges_[e].p1);
    const Edge& f = edges_[fi];
    if (fi == next_of(e) || fi == prev_of(e)) {
      // they share one vertex; the other end of f off e's line (a turn), or on it going straight on
      return !(orient(L.a, L.b, fi == next_of(e) ? f.p1 : f.p0) != 0 || same_way(L.a, L.b, f.p0, f.p1));
    }
    Cand::Kind kind{};
    return meets(L, f, kind);
  };
  for (std::uint32_t e = 0; e < ne; ++e) {
    const std::uint32_t c = comp[edges_[e].poly];
    if (bad[c]) continue;
    for (std::uint32_t k = near_start_[e]; k < near_start_[e + 1]; ++k) {
      const std::uint32_t fi = near_items_[k];
      if (fi > e && meet(e, fi)) {
        bad[c] = 1;
        break;
      }
    }
  }
  ring_simple_.assign(nr, 0);
  sr_side_.assign(nr, 0);
  std::size_t n = 0;
  // Which side of each ring the union is on: its orientation (at its lexicographically smallest vertex, a strict
  // convex corner of a simple ring), flipped where an odd number of its polygon's other rings contain it; none
  // where another polygon covers it.
  auto inside = [&](const Point2& v, std::uint32_t q) {  // v (on no ring of q) lies inside ring q
    sr_pts_.clear();
    for (std::uint32_t e = ring_first_[q]; e < ring_first_[q + 1]; ++e) sr_pts_.push_back(edges_[e].p0);
    return point_in_ring(v, sr_pts_);
  };
  // Polygons near a point through the grid (built here for the walk too) where a block has many: no query is
  // quadratic in the block's size. Rings of a polygon through their boxes (a point outside one is outside it).
  if (np > 16) {
    poly_grid_.build(pboxes_, all_, np + 1);
    poly_grid_built_ = true;
  }
  auto polys_at = [&](const Point2& v, auto&& f) {
    if (poly_grid_built_) {
      Box pb;
      pb.add(v);
      poly_grid_.query(pb, f);
    } else {
      for (std::uint32_t o = 0; o < np; ++o) f(o);
    }
  };
  std::vector<Box>& rbox = sr_rbox_;
  for (std::uint32_t p = 0; p < np; ++p) {
    if (bad[comp[p]]) continue;
    const Poly& P = polys_[p];
    const std::uint32_t r0 = edge_ring_[P.first_edge], r1 = edge_ring_[P.end_edge - 1] + 1;
    if (r1 - r0 > 1) {
      rbox.assign(r1 - r0, Box{});
      for (std::uint32_t e = P.first_edge; e < P.end_edge; ++e) rbox[edge_ring_[e] - r0].add(edges_[e].p0);
    }
    for (std::uint32_t r = r0; r < r1; ++r) {
      std::uint32_t m = ring_first_[r];
      for (std::uint32_t e = m + 1; e < ring_first_[r + 1]; ++e) {
        const Point2& q = edges_[e].p0;
        if (q.x < edges_[m].p0.x || (q.x == edges_[m].p0.x && q.y < edges_[m].p0.y)) m = e;
      }
      int side = orient(edges_[prev_of(m)].p0, edges_[m].p0, edges_[m].p1);
      const Point2& v = edges_[ring_first_[r]].p0;
      int depth = 0;
      for (std::uint32_t q = r0; q < r1 && side != 0; ++q) {
        if (q == r || !rbox[q - r0].contains(v)) continue;
        const int in = inside(v, q);
        if (in == 0) side = 0;  // cannot happen: the rings do not meet
        depth += in > 0;
      }
      if (depth % 2 == 1) side = -side;
      // covered by another polygon of the component: the union on both sides, no boundary
      bool covered = false;
      polys_at(v, [&](std::uint32_t o) {
        if (covered || side == 0 || o == p || comp[o] != comp[p] || !polys_[o].box.contains(v)) return;
        const std::uint32_t q0 = edge_ring_[polys_[o].first_edge], q1 = edge_ring_[polys_[o].end_edge - 1] + 1;
        int odd = 0;
        for (std::uint32_t q = q0; q < q1; ++q) {
          const int in = inside(v, q);
          if (in == 0) side = 0;  // cannot happen
          odd ^= in > 0;
        }
        covered = odd != 0;
      });
      if (side == 0 && !covered) {
        bad[comp[p]] = 1;  // not simple after all: leave the whole component to the walk
        break;
      }
      sr_side_[r] = static_cast<signed char>(covered ? 0 : side);
    }
  }
  for (std::uint32_t p = 0; p < np; ++p) {
    if (bad[comp[p]]) continue;
    const Poly& P = polys_[p];
    for (std::uint32_t r = edge_ring_[P.first_edge]; r <= edge_ring_[P.end_edge - 1]; ++r) {
      ring_simple_[r] = 1;
      ++n;
    }
  }
  if (n > 0) stats_.simple_rings = 1;
  return n;
}

/// Takes ring r as a walk where simple_rings() found it a boundary, starting at edge e (forward: union on the
/// left of e) or, for the first ring (from_seed), at the rightmost vertex, edge e's start.
void BlockEngine::take_ring(std::uint32_t e, bool from_seed) {
  const std::uint32_t r = edge_ring_[e];
  ring_done_[r] = 1;
  if (sr_side_[r] == 0) return;  // covered by another polygon: no boundary
  ++stats_.edges_checked;
  if (from_seed && sr_side_[r] < 0) {
    // the rightmost vertex is a start of edge e and the end of the edge before it: counter-clockwise is backward
    const std::uint32_t first = ring_first_[r], end = ring_first_[r + 1];
    walk_ring(e == first ? end - 1 : e - 1, false);
    return;
  }
  walk_ring(e, sr_side_[r] > 0);
}

/// The walk of one ring found by mark_simple_rings(): forward from edge e's start (points e.p1, the next edge's end,
/// ..., e.p0), or backward from its end (e.p0, the previous edge's start, ..., e.p1), as walk() records them.
void BlockEngine::walk_ring(std::uint32_t e, bool forward) {
  const std::uint32_t r = edge_ring_[e], first = ring_first_[r], end = ring_first_[r + 1];
  RingOut ring;
  ring.pts.reserve(end - first);
  if (forward) {
    for (std::uint32_t k = e; k < end; ++k) ring.pts.push_back(edges_[k].p1);
    for (std::uint32_t k = first; k < e; ++k) ring.pts.push_back(edges_[k].p1);
  } else {
    for (std::uint32_t k = e + 1; k-- > first;) ring.pts.push_back(edges_[k].p0);
    for (std::uint32_t k = end; k-- > e + 1;) ring.pts.push_back(edges_[k].p0);
  }
  ring.polys.push_back(edges_[e].poly);
  stats_.walk_steps += end - first;
  ++stats_.rings_traced;
  rings_.push_back(std::move(ring));
}

// ------------------------------------------------------------------------------------------------
int BlockEngine::cmp(const Line& L, const Event& x, const Event& y) const {
  if (!x.cross && !y.cross) return L.cmp_vv(x.v, y.v);
  if (x.cross && y.cross) {
    if (x.f == y.f) return 0;
    const Edge& f = edges_[x.f];
    const Edge& g = edges_[y.f];
    return robust::compare_crossings(L.a, L.b, f.p0, f.p1, g.p0, g.p1);
  }
  // vertex v (on the line) against the crossing X with f: O_f is linear along the line, zero at X,
  // and O_f(a) - O_f(b) = (b - a) x (f1 - f0); so v comes first iff sign O_f(v) is that sign.
  const bool flip = x.cross;
  const Point2& v = flip ? y.v : x.v;
  const Edge& f = edges_[flip ? x.f : y.f];
  const int sv = orient(f.p0, f.p1, v);
  int r = 0;
  if (sv != 0) r = (sv == cross_sign(L.a, L.b, f.p0, f.p1)) ? -1 : 1;
  return flip ? -r : r;
}

void BlockEngine::build_near_lists(const std::vector<Box>& boxes) {
  const std::size_t n = boxes.size();
  std::vector<std::uint32_t>& order = sweep_order_;
  order.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return boxes[a].minx < boxes[b].minx; });
  // pairs (a, b) with meeting boxes, found by a sweep over x; stored both ways
  std::vector<std::uint32_t>& act = sweep_active_;
  act.clear();
  std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs = pair_scratch_;
  pairs.clear();
  for (std::uint32_t i : order) {
    const Box& b = boxes[i];
    std::size_t w = 0;
    for (std::size_t r = 0; r < act.size(); ++r) {
      const std::uint32_t j = act[r];
      if (boxes[j].maxx < b.minx) continue;  // left behind for good
      act[w++] = j;
      if (boxes[j].miny <= b.maxy && b.miny <= boxes[j].maxy) {
        pairs.emplace_back(i, j);
        pairs.emplace_back(j, i);
      }
    }
    act.resize(w);
    act.push_back(i);
  }
  near_start_.assign(n + 1, 0);
  for (const auto& p : pairs) ++near_start_[p.first + 1];
  for (std::size_t k = 1; k <= n; ++k) near_start_[k] += near_start_[k - 1];
  near_items_.resize(pairs.size());
  std::vector<std::uint32_t>& fill = sweep_order_;  // reuse
  fill.assign(near_start_.begin(), near_start_.end() - 1);
  for (const auto& p : pairs) near_items_[fill[p.first]++] = p.second;
}

void BlockEngine::scan(const Line& L, std::vector<Cand>& out) {
  out.clear();
  for (std::uint32_t k = near_start_[L.e]; k < near_start_[L.e + 1]; ++k) {
    const std::uint32_t fi = near_items_[k];
    Cand::Kind kind{};
    if (meets(L, edges_[fi], kind)) out.push_back({fi, kind});
  }
}

/// The event of candidate c (which = 0/1 selects a collinear edge's endpoint).
Event BlockEngine::event_of(const Line& L, const Cand& c, int which) const {
  const Edge& f = edges_[c.edge];
  switch (c.kind) {
    case Cand::Crossing: return Event{true, {}, c.edge};
    case Cand::Touch0: return Event{false, f.p0, 0};
    case Cand::Touch1: return Event{false, f.p1, 0};
    case Cand::PassA: return Event{false, L.a, 0};
    case Cand::PassB: return Event{false, L.b, 0};
    case Cand::Collinear: return Event{false, which == 0 ? f.p0 : f.p1, 0};
  }
  return {};
}

void BlockEngine::rays_at(const Line& L, const Event& x, const std::vector<Cand>& cands, std::vector<Ray>& out) const {
  out.clear();
  const Edge& e = edges_[L.e];
  {
    const int ca = cmp(L, Event{false, L.a, 0}, x), cb = cmp(L, Event{false, L.b, 0}, x);
    if (ca == 0) {
      out.push_back({L.a, L.b, L.e, e.poly});
    } else if (cb == 0) {
      out.push_back({L.b, L.a, L.e, e.poly});
    } else {
      out.push_back({L.a, L.b, L.e, e.poly});
      out.push_back({L.b, L.a, L.e, e.poly});
    }
  }
  for (const Cand& c : cands) {
    const Edge& f = edges_[c.edge];
    switch (c.kind) {
      case Cand::Crossing:
      case Cand::PassA:
      case Cand::PassB:
        if (cmp(L, event_of(L, c, 0), x) == 0) {
          out.push_back({f.p0, f.p1, c.edge, f.poly});
          out.push_back({f.p1, f.p0, c.edge, f.poly});
        }
        break;
      case Cand::Touch0:
        if (cmp(L, Event{false, f.p0, 0}, x) == 0) out.push_back({f.p0, f.p1, c.edge, f.poly});
        break;
      case Cand::Touch1:
        if (cmp(L, Event{false, f.p1, 0}, x) == 0) out.push_back({f.p1, f.p0, c.edge, f.poly});
        break;
      case Cand::Collinear: {
        const int c0 = cmp(L, Event{false, f.p0, 0}, x), c1 = cmp(L, Event{false, f.p1, 0}, x);
        if (c0 == 0) {
          out.push_back({f.p0, f.p1, c.edge, f.poly});
        } else if (c1 == 0) {
          out.push_back({f.p1, f.p0, c.edge, f.poly});
        } else if ((c0 < 0) != (c1 < 0)) {
          out.push_back({f.p0, f.p1, c.edge, f.poly});
          out.push_back({f.p1, f.p0, c.edge, f.poly});
        }
        break;
      }
    }
  }
}

// ------------------------------------------------------------------------------------------------
// Angular classes counter-clockwise from the reference r0->r1: 0 = (0, pi), 1 = pi, 2 = (pi, 2pi),
// 3 = the reference direction itself (swept last, as 2pi).
int BlockEngine::ray_class(const Point2& r0, const Point2& r1, const Ray& d) const {
  const int c = cross_sign(r0, r1, d.from, d.to);
  if (c > 0) return 0;
  if (c < 0) return 2;
  return same_way(r0, r1, d.from, d.to) ? 3 : 1;
}

void BlockEngine::sort_rays(const Point2& r0, const Point2& r1, std::vector<Ray>& rays) const {
  std::vector<std::pair<int, Ray>>& k = sort_scratch_;
  k.clear();
  for (const Ray& r : rays) k.emplace_back(ray_class(r0, r1, r), r);
  auto less = [&](const std::pair<int, Ray>& x, const std::pair<int, Ray>& y) {
    if (x.first != y.first) return x.first < y.first;
    if (x.first == 1 || x.first == 3) return x.second.edge < y.second.edge;
    const int c = cross_sign(x.second.from, x.second.to, y.second.from, y.second.to);
    if (c != 0) return c > 0;
    return x.second.edge < y.second.edge;
  };
  if (k.size() <= 12) {
    // a handful of rays meet at a vertex: insertion sort, no allocation
    for (std::size_t i = 1; i < k.size(); ++i)
      for (std::size_t j = i; j > 0 && less(k[j], k[j - 1]); --j) std::swap(k[j], k[j - 1]);
  } else {
    std::stable_sort(k.begin(), k.end(), less);
  }
  for (std::size_t i = 0; i < rays.size(); ++i) rays[i] = k[i].second;
}

bool BlockEngine::same_group(const Point2& r0, const Point2& r1, const Ray& x, const Ray& y) const {
  return cross_sign(x.from, x.to, y.from, y.to) == 0 && same_way(x.from, x.to, y.from, y.to);
}

/// Sweeps the sorted rays counter-clockwise from the reference, starting with `state` (the parity
/// of the wedge just after the reference, outside the union), and returns the LAST group [g0, g1)
/// where the sweep enters the union: the wedge before it is outside, the wedge after it inside.
/// Walking that group keeps the exterior on the right; taking the last such group rather than the
/// first links the rings as minimal rings (each ring bounds one face of the union locally), which
/// is how GEOS links them: two footprints touching at a point are two plans, a pentagram is five
/// triangles, and a hole touching its shell at one point comes out as a closed walk that revisits
/// that point and is split there into shell and hole.
bool BlockEngine::choose_outgoing(const Point2& r0, const Point2& r1, std::vector<Ray>& rays, std::size_t& g0,
                                  std::size_t& g1, Parity state) const {
  sort_rays(r0, r1, rays);
  bool found = false;
  std::size_t i = 0;
  while (i < rays.size()) {
    std::size_t j = i + 1;
    while (j < rays.size() && same_group(r0, r1, rays[i], rays[j])) ++j;
    // the reference direction itself closes the sweep: never an outgoing direction
    if (ray_class(r0, r1, rays[i]) == 3) break;
    const bool before = state.inside();
    for (std::size_t k = i; k < j; ++k) state.toggle(rays[k].poly);
    if (!before && state.inside()) {
      g0 = i;
      g1 = j;
      found = true;
    }
    i = j;
  }
  return found;
}

Point2 BlockEngine::point_of(const Line& L, const Event& x) const {
  if (!x.cross) return x.v;
  const Edge& f = edges_[x.f];
  return robust::crossing_point(L.a, L.b, f.p0, f.p1);
}

void BlockEngine::mark(const std::vector<Ray>& group, const Line& L, const Event& s, const Event& t) {
  for (const Ray& r : group) {
    const Edge& h = edges_[r.edge];
    // store ordered along h's own direction: same way as L or opposite
    const bool same = same_way(L.a, L.b, h.p0, h.p1);
    pieces_.push_back(same ? Piece{s, t, first_piece_[r.edge]} : Piece{t, s, first_piece_[r.edge]});
    first_piece_[r.edge] = static_cast<std::uint32_t>(pieces_.size() - 1);
  }
}

void BlockEngine::walk(Line L, Event start, std::vector<Ray> group) {
  const Line L0 = L;
  const Event start0 = start;
  RingOut ring;
  Event cur = start;
  std::vector<Cand>& cands = scratch_cands_;
  std::vector<Ray>& rays = walk_rays_;
  std::vector<robust::Segment>& segs = walk_segs_;
  std::vector<std::uint32_t>& seg_edges = walk_seg_edges_;
  std::vector<ExactVertex>& exact = walk_exact_;
  exact.clear();
  std::uint32_t scanned_edge = kNone;
  Point2 scanned_from;
  for (std::size_t step = 0;; ++step) {
    if (step > step_limit_) {
      const Point2 p = point_of(L, cur);
      throw TopologyError("boundary walk did not close (groundplan bug; please report with the input)", p.x, p.y);
    }
    ++stats_.walk_steps;
    // continuing straight along the same edge (a T-junction on an outer wall): same candidates
    if (!(step > 0 && L.e == scanned_edge && L.a == scanned_from)) scan(L, cands);
    scanned_edge = L.e;
    scanned_from = L.a;
    // Lemma 1: the nearest event after cur.
    Event best_v{false, L.b, 0};  // the edge's own end is always an event
    segs.clear();
    seg_edges.clear();
    for (const Cand& c : cands) {
      if (c.kind == Cand::Crossing) {
        const Event ev{true, {}, c.edge};
        if (cmp(L, ev, cur) > 0) {
          segs.push_back({edges_[c.edge].p0, edges_[c.edge].p1});
          seg_edges.push_back(c.edge);
        }
        continue;
      }
      for (int w = 0; w < (c.kind == Cand::Collinear ? 2 : 1); ++w) {
        const Event ev = event_of(L, c, w);
        if (c.kind == Cand::Collinear && !L.within(ev.v)) continue;
        if (cmp(L, ev, cur) > 0 && L.cmp_vv(ev.v, best_v.v) < 0) best_v = ev;
      }
    }
    Event x0 = best_v;
    if (!segs.empty()) {
      const std::vector<std::size_t> near = robust::nearest_crossings(L.a, L.b, segs);
      const Event xc{true, {}, seg_edges[near[0]]};
      if (cmp(L, xc, best_v) < 0) x0 = xc;
    }
    {
      // members: polygons entered by the group we are walking along
      Parity pg;
      for (const Ray& r : group) pg.toggle(r.poly);
      pg.for_each([&](std::uint32_t p) {
        if (std::find(ring.polys.begin(), ring.polys.end(), p) == ring.polys.end()) ring.polys.push_back(p);
      });
    }
    mark(group, L, cur, x0);
    rays_at(L, x0, cands, rays);
    std::size_t g0 = 0, g1 = 0;
    // A plain corner: the ray back along this edge (the reference, swept last) and one other, which the sweep
    // from the exterior enters the union by: choose_outgoing would return it alone, so no sort is needed.
    if (rays.size() == 2 && rays[0].edge == L.e && ray_class(L.b, L.a, rays[0]) == 3 && ray_class(L.b, L.a, rays[1]) != 3) {
      g0 = 1;
      g1 = 2;
    } else if (!choose_outgoing(L.b, L.a, rays, g0, g1, Parity{})) {
      const Point2 p = point_of(L, x0);
      throw TopologyError("boundary walk found no way out of a vertex (groundplan bug; please report)", p.x, p.y);
    }
    // the lowest edge id of the group continues the walk (deterministic)
    std::size_t pick = g0;
    for (std::size_t k = g0; k < g1; ++k)
      if (rays[k].edge < rays[pick].edge) pick = k;
    const Ray out = rays[pick];
    Event next = x0;
    if (x0.cross && cross_sign(L.a, L.b, out.from, out.to) != 0) next = Event{true, {}, L.e};
    // every event point is kept here: a straight run may pass a point the walk turns at later
    // (the ring touches itself there); split_simple needs to see it, then drops straight vertices
    ring.pts.push_back(point_of(L, x0));
    ring.rounded |= x0.cross;
    exact.push_back(ExactVertex{L.a, L.b, x0.cross ? edges_[x0.f].p0 : Point2{}, x0.cross ? edges_[x0.f].p1 : Point2{},
                                x0.cross});
    group.assign(rays.begin() + static_cast<std::ptrdiff_t>(g0), rays.begin() + static_cast<std::ptrdiff_t>(g1));
    L = Line(out.edge, out.from, out.to);
    cur = next;
    // closed when we leave the start point again in the start direction
    if (cross_sign(L0.a, L0.b, L.a, L.b) == 0 && same_way(L0.a, L0.b, L.a, L.b) && orient(L0.a, L0.b, L.a) == 0 &&
        cmp(L0, cur, start0) == 0)
      break;
  }
  if (ring.rounded) ring.exact = exact;  // the others are exact as they are
  ++stats_.rings_traced;
  rings_.push_back(std::move(ring));
}

// ------------------------------------------------------------------------------------------------
bool BlockEngine::walked(std::uint32_t e, const Line& L, const Event& s, const Event& t) const {
  for (std::uint32_t k = first_piece_[e]; k != kNone; k = pieces_[k].next)
    if (cmp(L, pieces_[k].s, s) == 0 && cmp(L, pieces_[k].t, t) == 0) return true;
  return false;
}

bool BlockEngine::fully_walked(std::uint32_t e) {
  if (first_piece_[e] == kNone) return false;
  const Line L(e, edges_[e].p0, edges_[e].p1);
  {
    // the common case: one piece, the whole edge
    const Piece& p = pieces_[first_piece_[e]];
    if (p.next == kNone) return !p.s.cross && !p.t.cross && p.s.v == L.a && p.t.v == L.b;
  }
  auto& w = chain_scratch_;
  w.clear();
  for (std::uint32_t k = first_piece_[e]; k != kNone; k = pieces_[k].next) w.push_back(pieces_[k]);

  std::sort(w.begin(), w.end(), [&](const Piece& x, const Piece& y) { return cmp(L, x.s, y.s) < 0; });
  const Event a{false, L.a, 0}, b{false, L.b, 0};
  if (cmp(L, w.front().s, a) != 0) return false;
  for (std::size_t i = 0; i + 1 < w.size(); ++i)
    if (cmp(L, w[i].t, w[i + 1].s) != 0) return false;
  return cmp(L, w.back().t, b) == 0;
}

/// Parity of every polygon in the wedge just counter-clockwise of the +x ray at p: an exact ray
/// cast along y = p.y + eps, x > p.x + delta (0 < eps << delta infinitesimal). An edge counts when
/// it straddles that line (half-open: min y <= p.y < max y) and passes strictly right of p; edges
/// through p itself pass left of the perturbed start point.
Parity BlockEngine::parity_at_vertex_wedge0(const Point2& p) {
  Parity par;
  Box pb;
  pb.add(p);
  std::vector<std::uint32_t>& hits = poly_hits_;
  hits.clear();
  poly_grid_.query(pb, [&](std::uint32_t pi) {
    if (polys_[pi].box.contains(p)) hits.push_back(pi);
  });
  for (std::uint32_t pi : hits) {
    const Poly& P = polys_[pi];
    bool odd = false;
    for (std::uint32_t ei = P.first_edge; ei < P.end_edge; ++ei) {
      const Edge& e = edges_[ei];
      const bool up = e.p0.y < e.p1.y;
      const Point2& lo = up ? e.p0 : e.p1;
      const Point2& hi = up ? e.p1 : e.p0;
      if (!(lo.y <= p.y && p.y < hi.y)) continue;
      if (orient(lo, hi, p) > 0) odd = !odd;
    }
    if (odd) par.toggle(pi);
  }
  return par;
}

void BlockEngine::check_edge(std::uint32_t e) {
  if (checked_[e] || fully_walked(e)) return;
  ++stats_.edges_checked;
  const Edge E = edges_[e];
  const Line L(e, E.p0, E.p1);
  std::vector<Cand>& cands = chk_cands_;
  scan(L, cands);
  // all events strictly inside, exactly ordered and deduplicated
  std::vector<Event>& evs = chk_evs_;
  evs.clear();
  const Event A{false, L.a, 0}, B{false, L.b, 0};
  for (const Cand& c : cands) {
    for (int w = 0; w < (c.kind == Cand::Collinear ? 2 : 1); ++w) {
      const Event ev = event_of(L, c, w);
      if (!ev.cross && !L.within(ev.v)) continue;
      if (cmp(L, ev, A) > 0 && cmp(L, ev, B) < 0) evs.push_back(ev);
    }
  }
  // A collinear edge lying within this segment (an exact twin, or a shorter party wall along a
  // longer one) has a subset of these pieces: every edge meeting it meets this segment. When this
  // check ends, every boundary piece of the segment has been walked, and a walk records its pieces
  // on every edge of the collinear group it walks along, that edge included. So it needs no check
  // of its own.
  for (const Cand& c : cands) {
    if (c.kind != Cand::Collinear) continue;
    const Edge& f = edges_[c.edge];
    if (L.within(f.p0) && L.within(f.p1)) checked_[c.edge] = 1;
  }
  std::sort(evs.begin(), evs.end(), [&](const Event& x, const Event& y) { return cmp(L, x, y) < 0; });
  evs.erase(std::unique(evs.begin(), evs.end(), [&](const Event& x, const Event& y) { return cmp(L, x, y) == 0; }),
            evs.end());
  evs.insert(evs.begin(), A);
  evs.push_back(B);
  bool any_open = false;
  for (std::size_t i = 0; i + 1 < evs.size() && !any_open; ++i)
    if (!walked(e, L, evs[i], evs[i + 1])) any_open = true;
  if (!any_open) return;

  // Parity on both sides at a: ray cast into the wedge above +x, then sweep to the edge.
  std::vector<Ray>& rays = chk_rays_;
  rays_at(L, A, cands, rays);
  Parity state = parity_at_vertex_wedge0(L.a);
  const Point2 o{0, 0}, xaxis{1, 0};
  sort_rays(o, xaxis, rays);
  // +x itself is swept last (class 3); find e's group and record the states around it
  Parity left, right;
  {
    std::size_t i = 0;
    bool found = false;
    while (i < rays.size()) {
      std::size_t j = i + 1;
      while (j < rays.size() && same_group(o, xaxis, rays[i], rays[j])) ++j;
      bool has_e = false;
      for (std::size_t k = i; k < j; ++k) has_e |= rays[k].edge == e;
      if (has_e) {
        right = state;
        for (std::size_t k = i; k < j; ++k) state.toggle(rays[k].poly);
        left = state;
        found = true;
        break;
      }
      for (std::size_t k = i; k < j; ++k) state.toggle(rays[k].poly);
      i = j;
    }
    if (!found) return;  // unreachable: e leaves its own start vertex
  }
  // The rays leaving to either side at each event strictly inside: those of the candidates whose event it is (a
  // crossing edge leaves to both sides, an edge touching L to the side of its other end; collinear ones to none),
  // each candidate put at its event once (binary search in the ordered events) instead of every candidate compared
  // with every event.
  std::vector<std::pair<std::size_t, std::uint32_t>>& at = chk_at_;  // (event index, candidate index)
  at.clear();
  if (evs.size() > 2) {
    const auto before = [&](const Event& x, const Event& y) { return cmp(L, x, y) < 0; };
    for (std::uint32_t k = 0; k < cands.size(); ++k) {
      const Cand& c = cands[k];
      if (c.kind != Cand::Crossing && c.kind != Cand::Touch0 && c.kind != Cand::Touch1) continue;
      const Event ev = event_of(L, c, 0);
      const auto it = std::lower_bound(evs.begin() + 1, evs.end() - 1, ev, before);
      if (it != evs.end() - 1 && cmp(L, *it, ev) == 0) at.emplace_back(static_cast<std::size_t>(it - evs.begin()), k);
    }
    std::sort(at.begin(), at.end());
  }
  std::size_t next_at = 0;
  for (std::size_t i = 0; i + 1 < evs.size(); ++i) {
    for (; next_at < at.size() && at[next_at].first == i; ++next_at) {
      const Cand& c = cands[at[next_at].second];
      const Edge& f = edges_[c.edge];
      if (c.kind == Cand::Crossing) {
        left.toggle(f.poly);
        right.toggle(f.poly);
        continue;
      }
      const int side = c.kind == Cand::Touch0 ? cross_sign(L.a, L.b, f.p0, f.p1) : cross_sign(L.a, L.b, f.p1, f.p0);
      if (side > 0) left.toggle(f.poly);
      if (side < 0) right.toggle(f.poly);
    }
    if (left.inside() == right.inside()) continue;
    if (walked(e, L, evs[i], evs[i + 1])) continue;
    // An unwalked boundary piece: a ring no seed has reached yet. Walk it with the exterior on
    // the right: forward if the union is on the left, else backward from the piece's far end.
    ++stats_.seeds_from_check;
    const bool fwd = left.inside();
    const Line W = fwd ? L : Line(e, L.b, L.a);
    const Event s = fwd ? evs[i] : evs[i + 1];
    std::vector<Cand>& wc = chk_wcands_;
    scan(W, wc);
    std::vector<Ray>& wr = chk_wrays_;
    std::vector<Ray> group;
    rays_at(W, s, wc, wr);
    for (const Ray& r : wr)
      if (cross_sign(W.a, W.b, r.from, r.to) == 0 && same_way(W.a, W.b, r.from, r.to)) group.push_back(r);
    walk(W, s, group);
  }
}


BlockResult BlockEngine::run() {
  BlockResult out;
  load();
  if (edges_.empty()) return out;
  // Rings apart from every other ring are taken as they are (mark_simple_rings); the others are walked.
  const std::size_t nr = ring_first_.size() - 1;
  const std::size_t n_simple = shortcut_ ? mark_simple_rings() : 0;
  if (n_simple == 0) ring_simple_.assign(nr, 0);
  ring_done_.assign(nr, 0);
  if (n_simple < nr && !poly_grid_built_) poly_grid_.build(pboxes_, all_, polys_.size() + 1);
  // §6.1: the rightmost vertex (then topmost) is on the boundary; the wedge above its +x ray is
  // exterior, so the sweep from +x finds the outgoing boundary edge (largest outward-normal x).
  std::uint32_t best = 0;
  for (std::uint32_t i = 1; i < edges_.size(); ++i) {
    const Point2& p = edges_[i].p0;
    const Point2& q = edges_[best].p0;
    if (p.x > q.x || (p.x == q.x && p.y > q.y)) best = i;
  }
  if (ring_simple_[edge_ring_[best]]) {
    take_ring(best, true);
  } else {
    const Point2 r = edges_[best].p0;
    const Line L(best, r, edges_[best].p1);
    std::vector<Cand> cands;
    scan(L, cands);
    std::vector<Ray> rays;
    rays_at(L, Event{false, r, 0}, cands, rays);
    std::size_t g0 = 0, g1 = 0;
    if (choose_outgoing(Point2{0, 0}, Point2{1, 0}, rays, g0, g1, Parity{})) {
      std::size_t pick = g0;
      for (std::size_t k = g0; k < g1; ++k)
        if (rays[k].edge < rays[pick].edge) pick = k;
      std::vector<Ray> group(rays.begin() + static_cast<std::ptrdiff_t>(g0),
                             rays.begin() + static_cast<std::ptrdiff_t>(g1));
      walk(Line(rays[pick].edge, rays[pick].from, rays[pick].to), Event{false, r, 0}, std::move(group));
    }
  }
  // Completeness (see the head of this file): every boundary piece of every edge is walked.
  // Longest edges first: a checked edge spares the collinear edges lying within it.
  std::vector<std::uint32_t>& order = check_order_;
  order.clear();
  for (std::uint32_t e = 0; e < edges_.size(); ++e)
    if (ring_simple_[edge_ring_[e]] ? !ring_done_[edge_ring_[e]] : !fully_walked(e)) order.push_back(e);
  auto len2 = [&](std::uint32_t e) {
    const double dx = edges_[e].p1.x - edges_[e].p0.x, dy = edges_[e].p1.y - edges_[e].p0.y;
    return dx * dx + dy * dy;
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const double la = len2(a), lb = len2(b);
    return la > lb || (la == lb && a < b);
  });
  for (std::uint32_t e : order) {
    if (!ring_simple_[edge_ring_[e]]) {
      check_edge(e);
    } else if (!ring_done_[edge_ring_[e]]) {
      take_ring(e, false);
    }
  }
  assemble(out);
  out.stats = stats_;
  return out;
}

}  // namespace

BlockResult union_block(const std::vector<Footprint>& footprints, const std::vector<std::uint32_t>& members,
                        double pitch, bool shortcut) {
  thread_local BlockEngine engine;
  engine.reset(footprints, members, pitch, shortcut);
  BlockResult r = engine.run();
  r.pitch = pitch;
  return r;
}

}  // namespace groundplan::detail

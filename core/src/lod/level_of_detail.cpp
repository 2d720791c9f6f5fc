// SPDX-License-Identifier: MIT
// The union stage with a level of detail (issue 9): the order of the steps, the paper's raster level
// of detail (holes that hold no whole pixel are filled), and the area filters. Snap, close gaps and
// simplify live in their own files. Every change is counted in LodStats and named by a Problem
// (stage "lod"): a filled hole by the plan's buildings, a dropped plan by each of its buildings.
#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>
#include <groundplan/raster_backend.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <string>

#include "lod/ring_geometry.h"
#include "robust/predicates.h"

namespace groundplan {
namespace {

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

using lod::ring_area2;

struct Box {
  double minx = std::numeric_limits<double>::infinity(), miny = minx;
  double maxx = -std::numeric_limits<double>::infinity(), maxy = maxx;
  void add(const Point2& p) {
    minx = std::min(minx, p.x), maxx = std::max(maxx, p.x);
    miny = std::min(miny, p.y), maxy = std::max(maxy, p.y);
  }
  bool contains(const Box& b) const { return b.minx >= minx && b.maxx <= maxx && b.miny >= miny && b.maxy <= maxy; }
};

Box ring_box(const Ring& r) {
  Box b;
  for (const Point2& p : r) b.add(p);
  return b;
}

/// Exact even-odd test: p strictly inside ring r (a point on the ring counts as outside).
bool strictly_inside(const Ring& r, const Point2& p) {
  bool odd = false;
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point2& a = r[i];
    const Point2& b = r[(i + 1) % n];
    if ((a.y > p.y) != (b.y > p.y)) {
      // Does the edge cross the ray to the right of p? Exact: the sign of orient(a, b, p) against
      // the edge's direction.
      const int o = robust::orient(a, b, p);
      if (o == 0) return false;
      if ((o > 0) == (b.y > a.y)) odd = !odd;
    } else if (robust::orient(a, b, p) == 0 && std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) &&
               std::min(a.y, b.y) <= p.y && p.y <= std::max(a.y, b.y)) {
      return false;  // on a horizontal edge or at a vertex
    }
  }
  return odd;
}

/// Is ring `r` (the outer ring of a plan disjoint from the hole's owner) inside hole `h`? Plans meet
/// at points only, so r's vertices are all inside h or on it, or all outside or on it. When every
/// vertex lies on h (a triangle wedged into three corners of the hole), an edge's midpoint decides:
/// r's edges are not on h (that would join the plans), so a midpoint is inside or outside.
bool ring_inside(const Ring& r, const Ring& h) {
  for (const Point2& p : r) {
    if (strictly_inside(h, p)) return true;
    bool on = false;
    for (std::size_t i = 0, n = h.size(); i < n && !on; ++i) {
      const Point2& a = h[i];
      const Point2& b = h[(i + 1) % n];
      on = robust::orient(a, b, p) == 0 && std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) &&
           std::min(a.y, b.y) <= p.y && p.y <= std::max(a.y, b.y);
    }
    if (!on) return false;
  }
  for (std::size_t i = 0, n = r.size(); i < n; ++i) {
    const Point2 m{(r[i].x + r[(i + 1) % n].x) / 2, (r[i].y + r[(i + 1) % n].y) / 2};
    if (strictly_inside(h, m)) return true;
  }
  return false;
}

/// "a, b, c (+N more)": the buildings of a plan, for a message.
std::string plan_ids(const GroundPlan& g, const std::vector<Footprint>& footprints) {
  std::string s;
  const std::size_t shown = std::min<std::size_t>(g.members.size(), 3);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i) s += ", ";
    const std::uint32_t m = g.members[i];
    s += m < footprints.size() ? footprints[m].source_id : std::to_string(m);
  }
  if (g.members.size() > shown) s += " (+" + std::to_string(g.members.size() - shown) + " more)";
  return s;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// The plans' outer-ring boxes sorted by their left edge: the plans whose box lies inside a given box
/// (a hole's: its candidate islands) are found by a range scan.
struct PlanIndex {
  std::vector<Box> boxes;
  std::vector<std::size_t> by_minx;
  explicit PlanIndex(const std::vector<GroundPlan>& plans) : boxes(plans.size()), by_minx(plans.size()) {
    for (std::size_t i = 0; i < plans.size(); ++i) boxes[i] = ring_box(plans[i].polygon.outer), by_minx[i] = i;
    std::sort(by_minx.begin(), by_minx.end(), [&](std::size_t a, std::size_t b) { return boxes[a].minx < boxes[b].minx; });
  }
  /// Calls f(j) for every plan j whose box lies inside `b`.
  template <class F>
  void for_each_inside(const Box& b, const F& f) const {
    auto it = std::lower_bound(by_minx.begin(), by_minx.end(), b.minx,
                               [&](std::size_t i, double x) { return boxes[i].minx < x; });
    for (; it != by_minx.end() && boxes[*it].minx <= b.maxx; ++it)
      if (b.contains(boxes[*it])) f(*it);
  }
};

/// Fills the holes of `plans` for which `fill(plan, hole, index)` says so. A plan inside a filled hole (an
/// island) would now overlap its owner: it joins the owner (members merged), so the plans stay
/// non-overlapping. Returns the number of holes filled and adds their area to *area.
template <class Fill>
std::size_t fill_holes(std::vector<GroundPlan>& plans, const Fill& fill, const std::vector<Footprint>& footprints,
                       std::vector<Problem>& problems, const char* code, const std::string& why, double* area) {
  const PlanIndex index(plans);
  std::vector<char> absorbed(plans.size(), 0);
  std::size_t filled = 0;
  for (std::size_t pi = 0; pi < plans.size(); ++pi) {
    if (absorbed[pi]) continue;
    GroundPlan& g = plans[pi];
    std::vector<Ring> kept;
    for (Ring& h : g.polygon.holes) {
      if (!fill(g, h, index)) {
        kept.push_back(std::move(h));
        continue;
      }
      ++filled;
      const double a = static_cast<double>(std::fabs(ring_area2(h)) / 2);
      *area += a;
      const Box hb = ring_box(h);
      std::size_t islands = 0;
      index.for_each_inside(hb, [&](std::size_t j) {
        if (j == pi || absorbed[j] || !ring_inside(plans[j].polygon.outer, h)) return;
        absorbed[j] = 1;
        ++islands;
        std::vector<std::uint32_t> merged;
        std::set_union(g.members.begin(), g.members.end(), plans[j].members.begin(), plans[j].members.end(),
                       std::back_inserter(merged));
        g.members = std::move(merged);
      });
      Point2 c = h[0];
      const std::string file =
          !g.members.empty() && g.members[0] < footprints.size() ? footprints[g.members[0]].source_file : "";
      problems.push_back(Problem{plan_ids(g, footprints), file, "lod", code,
                                 "hole of " + fmt("%.3g", a) + " m2 near (" + fmt("%.3f", c.x) + ", " +
                                     fmt("%.3f", c.y) + ") filled: " + why +
                                     (islands ? " (" + std::to_string(islands) + " plan(s) inside it joined this one)"
                                              : std::string())});
    }
    g.polygon.holes = std::move(kept);
    g.area_m2 = polygon_area(g.polygon);
  }
  std::size_t w = 0;
  for (std::size_t i = 0; i < plans.size(); ++i)
    if (!absorbed[i]) {
      if (w != i) plans[w] = std::move(plans[i]);
      ++w;
    }
  plans.resize(w);
  return filled;
}

/// Does the closed segment pq meet the closed box [x0,x1]x[y0,y1]? (Liang-Barsky; a level-of-detail
/// decision, so double precision is enough.)
bool segment_meets_box(const Point2& p, const Point2& q, double x0, double y0, double x1, double y1) {
  double t0 = 0, t1 = 1;
  const double dx = q.x - p.x, dy = q.y - p.y;
  auto clip = [&](double den, double num) {  // den * t <= num
    if (den == 0) return num >= 0;
    const double t = num / den;
    if (den > 0) {
      if (t < t0) return false;
      t1 = std::min(t1, t);
    } else {
      if (t > t1) return false;
      t0 = std::max(t0, t);
    }
    return t0 <= t1;
  };
  return clip(-dx, p.x - x0) && clip(dx, x1 - p.x) && clip(-dy, p.y - y0) && clip(dy, y1 - p.y);
}

/// The paper's Update sees a hole only through an empty pixel inside it: true when some pixel of
/// `grid` lies wholly inside hole `h` and touches no plan (islands in the hole included).
bool hole_holds_a_pixel(const Ring& h, const std::vector<const GroundPlan*>& near, const PixelGrid& grid) {
  const double res = grid.resolution_m;
  const Box hb = ring_box(h);
  if (static_cast<double>(std::fabs(ring_area2(h)) / 2) < res * res) return false;  // no room for one pixel
  const auto c0 = static_cast<std::int64_t>(std::ceil((hb.minx - grid.origin_x) / res));
  const auto c1 = static_cast<std::int64_t>(std::floor((hb.maxx - grid.origin_x) / res)) - 1;
  const auto r0 = static_cast<std::int64_t>(std::ceil((hb.miny - grid.origin_y) / res));
  const auto r1 = static_cast<std::int64_t>(std::floor((hb.maxy - grid.origin_y) / res)) - 1;
  for (std::int64_t r = r0; r <= r1; ++r)
    for (std::int64_t c = c0; c <= c1; ++c) {
      const double x0 = grid.origin_x + static_cast<double>(c) * res, x1 = x0 + res;
      const double y0 = grid.origin_y + static_cast<double>(r) * res, y1 = y0 + res;
      const Point2 centre{(x0 + x1) / 2, (y0 + y1) / 2};
      if (!strictly_inside(h, centre)) continue;
      bool blocked = false;
      for (std::size_t i = 0; i < h.size() && !blocked; ++i)
        blocked = segment_meets_box(h[i], h[(i + 1) % h.size()], x0, y0, x1, y1);
      for (const GroundPlan* g : near) {
        if (blocked) break;
        auto ring_blocks = [&](const Ring& r) {
          for (std::size_t i = 0; i < r.size(); ++i)
            if (segment_meets_box(r[i], r[(i + 1) % r.size()], x0, y0, x1, y1)) return true;
          return false;
        };
        blocked = ring_blocks(g->polygon.outer);
        for (const Ring& gh : g->polygon.holes)
          if (!blocked) blocked = ring_blocks(gh);
        // A pixel wholly inside an island touches no edge: test its centre.
        if (!blocked && strictly_inside(g->polygon.outer, centre)) {
          bool in_island_hole = false;
          for (const Ring& gh : g->polygon.holes) in_island_hole = in_island_hole || strictly_inside(gh, centre);
          blocked = !in_island_hole;
        }
      }
      if (!blocked) return true;
    }
  return false;
}

void check_param(const char* name, double v) {
  if (!std::isfinite(v) || v < 0)
    throw InvalidArgument(std::string(name) + " must be a finite number >= 0 (0 = off), got " + fmt("%g", v));
}

}  // namespace

double polygon_area(const Polygon& polygon) {
  long double a = std::fabs(ring_area2(polygon.outer));
  for (const Ring& h : polygon.holes) a -= std::fabs(ring_area2(h));
  return static_cast<double>(a / 2);
}

std::vector<GroundPlan> build_ground_plans(const std::vector<Footprint>& footprints, const UnionParams& union_params,
                                           const LodParams& lod, std::vector<Problem>& problems,
                                           const Progress& progress, LodStats* stats) {
  check_param("snap", lod.snap_m);
  check_param("close-gaps", lod.close_gaps_m);
  check_param("min-hole-area", lod.min_hole_area_m2);
  check_param("min-area", lod.min_area_m2);
  check_param("simplify", lod.simplify_m);
  LodStats local;
  LodStats& st = stats ? *stats : local;
  if (!lod.any()) return build_ground_plans(footprints, union_params, problems, progress);
  // The steps below change the union's plans: no feed sees them before they are final (the feed is never begun).
  UnionParams exact_params = union_params;
  exact_params.feed = nullptr;

  // 1. Snap the footprints (their copies: the footprints layer keeps what the source said).
  const std::vector<Footprint>* src = &footprints;
  std::vector<Footprint> snapped;
  if (lod.snap_m > 0) {
    const auto t0 = clock_type::now();
    snapped = snap_footprints(footprints, lod.snap_m, &st);
    if (snapped.size() != footprints.size())
      throw Error("snap_footprints changed the number of footprints (internal error)");
    src = &snapped;
    st.snap_s = seconds_since(t0);
  }
  // 2. The exact union.
  std::vector<GroundPlan> plans = build_ground_plans(*src, exact_params, problems, progress.sub(0, 0.8));
  // 3. Gaps and cavities narrower than D.
  if (lod.close_gaps_m > 0) {
    const auto t0 = clock_type::now();
    plans = close_gaps(plans, lod.close_gaps_m, exact_params, &st);
    st.close_s = seconds_since(t0);
    if (st.close_plans_failed)
      problems.push_back(Problem{"", "", "lod", "CLOSE_GAPS_FAILED",
                                 std::to_string(st.close_plans_failed) +
                                     " plan(s) are written without --close-gaps: the union inside the closing "
                                     "failed on them (please report the input)"});
    progress.report(0.85, "closing gaps");
  }
  // 4. The paper's level of detail: holes the raster cannot see.
  if (lod.raster) {
    const auto t0 = clock_type::now();
    // The pixel is the user's --resolution as given (the blocks raster may be coarser: it only groups
    // footprints), or the paper's rule: the smallest footprint's box covers 4 pixels.
    const FootprintSet fps = make_footprint_set(*src);
    PixelGrid grid = make_pixel_grid(fps, union_params.resolution_m);
    if (union_params.resolution_m > 0) {
      grid.resolution_m = union_params.resolution_m;
    } else {
      double smallest = std::numeric_limits<double>::infinity();
      for (const FootprintSet::Box& b : fps.boxes)
        if ((b.maxx - b.minx) * (b.maxy - b.miny) > 0) smallest = std::min(smallest, (b.maxx - b.minx) * (b.maxy - b.miny));
      if (std::isfinite(smallest)) grid.resolution_m = std::sqrt(smallest / 4);
    }
    st.raster_pixel_m = grid.resolution_m;
    auto fill = [&](const GroundPlan& owner, const Ring& h, const PlanIndex& index) {
      std::vector<const GroundPlan*> near;  // candidate islands: plans whose box lies in the hole's
      index.for_each_inside(ring_box(h), [&](std::size_t j) {
        if (&plans[j] != &owner) near.push_back(&plans[j]);
      });
      return !hole_holds_a_pixel(h, near, grid);
    };
    double area = 0;
    st.raster_holes_filled = fill_holes(plans, fill, footprints, problems, "HOLE_BELOW_PIXEL",
                                        "it holds no whole " + fmt("%g", grid.resolution_m) +
                                            " m pixel (--resolution-mode raster)",
                                        &area);
    st.raster_s = seconds_since(t0);
  }
  // 5. Simplify.
  if (lod.simplify_m > 0) {
    const auto t0 = clock_type::now();
    plans = simplify_plans(plans, lod.simplify_m, &st);
    st.simplify_s = seconds_since(t0);
    progress.report(0.95, "simplifying");
  }
  // 6. Small holes, then small plans.
  const auto t_filter = clock_type::now();
  if (lod.min_hole_area_m2 > 0) {
    const double a_min = lod.min_hole_area_m2;
    auto fill = [&](const GroundPlan&, const Ring& h, const PlanIndex&) { return std::fabs(ring_area2(h)) / 2 < a_min; };
    st.holes_filled += fill_holes(plans, fill, footprints, problems, "HOLE_BELOW_MIN_AREA",
                                  "smaller than --min-hole-area " + fmt("%g", a_min) + " m2", &st.holes_filled_area_m2);
  }
  if (lod.min_area_m2 > 0) {
    std::size_t w = 0;
    for (std::size_t i = 0; i < plans.size(); ++i) {
      GroundPlan& g = plans[i];
      if (g.area_m2 < lod.min_area_m2) {
        ++st.plans_dropped;
        st.plans_dropped_area_m2 += g.area_m2;
        for (std::uint32_t m : g.members)
          problems.push_back(Problem{m < footprints.size() ? footprints[m].source_id : std::string(),
                                     m < footprints.size() ? footprints[m].source_file : std::string(), "lod",
                                     "PLAN_BELOW_MIN_AREA",
                                     "its ground plan (" + fmt("%.3g", g.area_m2) + " m2, " +
                                         std::to_string(g.members.size()) +
                                         " building(s)) is smaller than --min-area " + fmt("%g", lod.min_area_m2) +
                                         " m2: not written"});
        continue;
      }
      if (w != i) plans[w] = std::move(g);
      ++w;
    }
    plans.resize(w);
  }
  st.filter_s = seconds_since(t_filter);
  progress.report(1.0, "ground plans");
  return plans;
}

}  // namespace groundplan

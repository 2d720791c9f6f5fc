// SPDX-License-Identifier: MIT
// Anchors for bench_union (union_anchors.h): Clipper2 and Boost.Polygon on the same footprints.
#include "union_anchors.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

#ifdef GROUNDPLAN_BENCH_CLIPPER2
#include <clipper2/clipper.h>
#endif
#ifdef GROUNDPLAN_BENCH_BOOST_POLYGON
#include <boost/polygon/polygon.hpp>
#endif

namespace groundplan::bench {
namespace {

using I = long long;
struct IPoint {
  I x, y;
};
using IRing = std::vector<IPoint>;

I to_micrometres(double v) { return std::llround(v * 1e6); }

/// Twice the signed area (positive: counter-clockwise), exact enough for an orientation in long double.
long double area2(const IRing& r) {
  long double a = 0;
  for (std::size_t i = 0, n = r.size(); i < n; ++i)
    a += static_cast<long double>(r[i].x) * r[(i + 1) % n].y - static_cast<long double>(r[(i + 1) % n].x) * r[i].y;
  return a;
}

/// Per footprint, its rings as integers (outer rings CCW, holes CW) and their box.
struct IntFootprints {
  struct Fp {
    std::vector<IRing> rings;
    I minx, miny, maxx, maxy;
  };
  std::vector<Fp> fps;
  explicit IntFootprints(const std::vector<Footprint>& footprints) {
    for (const Footprint& f : footprints) {
      Fp out{{}, 0, 0, 0, 0};
      bool first = true;
      auto add = [&](const Ring& r, bool outer) {
        IRing ir;
        for (const Point2& p : r) {
          const IPoint q{to_micrometres(p.x), to_micrometres(p.y)};
          if (ir.empty() || ir.back().x != q.x || ir.back().y != q.y) ir.push_back(q);
          out.minx = first ? q.x : std::min(out.minx, q.x);
          out.miny = first ? q.y : std::min(out.miny, q.y);
          out.maxx = first ? q.x : std::max(out.maxx, q.x);
          out.maxy = first ? q.y : std::max(out.maxy, q.y);
          first = false;
        }
        if (ir.size() < 3) return;
        if ((area2(ir) > 0) != outer) std::reverse(ir.begin(), ir.end());
        out.rings.push_back(std::move(ir));
      };
      for (const Polygon& p : f.polygons) {
        add(p.outer, true);
        for (const Ring& h : p.holes) add(h, false);
      }
      if (!out.rings.empty()) fps.push_back(std::move(out));
    }
  }
  /// Groups of footprints whose closed boxes meet, transitively: sweep over x and union-find.
  std::vector<std::vector<std::uint32_t>> groups() const {
    const auto n = static_cast<std::uint32_t>(fps.size());
    std::vector<std::uint32_t> order(n), parent(n), active;
    std::iota(order.begin(), order.end(), 0u);
    std::iota(parent.begin(), parent.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return fps[a].minx < fps[b].minx; });
    auto find = [&](std::uint32_t a) {
      while (parent[a] != a) a = parent[a] = parent[parent[a]];
      return a;
    };
    for (std::uint32_t i : order) {
      std::size_t w = 0;
      for (std::uint32_t j : active) {
        if (fps[j].maxx < fps[i].minx) continue;
        active[w++] = j;
        if (fps[j].miny <= fps[i].maxy && fps[i].miny <= fps[j].maxy) parent[find(i)] = find(j);
      }
      active.resize(w);
      active.push_back(i);
    }
    std::vector<std::uint32_t> slot(n, UINT32_MAX);
    std::vector<std::vector<std::uint32_t>> out;
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t r = find(i);
      if (slot[r] == UINT32_MAX) {
        slot[r] = static_cast<std::uint32_t>(out.size());
        out.emplace_back();
      }
      out[slot[r]].push_back(i);
    }
    return out;
  }
};

#ifdef GROUNDPLAN_BENCH_CLIPPER2
Clipper2Lib::Path64 to_clipper(const IRing& r) {
  Clipper2Lib::Path64 p;
  p.reserve(r.size());
  for (const IPoint& q : r) p.emplace_back(q.x, q.y);
  return p;
}

std::size_t outer_rings(const Clipper2Lib::Paths64& ps) {
  std::size_t n = 0;
  for (const auto& p : ps) n += Clipper2Lib::Area(p) > 0;
  return n;
}

struct ClipperOne : Anchor {
  Clipper2Lib::Paths64 paths;
  explicit ClipperOne(const IntFootprints& in) {
    for (const auto& f : in.fps)
      for (const IRing& r : f.rings) paths.push_back(to_clipper(r));
  }
  std::size_t run() override { return outer_rings(Clipper2Lib::Union(paths, Clipper2Lib::FillRule::NonZero)); }
};

struct ClipperGroups : Anchor {
  IntFootprints in;
  std::vector<Clipper2Lib::Paths64> paths;  // per footprint
  explicit ClipperGroups(IntFootprints f) : in(std::move(f)) {
    for (const auto& fp : in.fps) {
      paths.emplace_back();
      for (const IRing& r : fp.rings) paths.back().push_back(to_clipper(r));
    }
  }
  std::size_t run() override {
    std::size_t n = 0;
    Clipper2Lib::Paths64 group;
    for (const auto& g : in.groups()) {
      group.clear();
      for (std::uint32_t i : g) group.insert(group.end(), paths[i].begin(), paths[i].end());
      n += outer_rings(Clipper2Lib::Union(group, Clipper2Lib::FillRule::NonZero));
    }
    return n;
  }
};
#endif

#ifdef GROUNDPLAN_BENCH_BOOST_POLYGON
namespace bp = boost::polygon;
struct BoostAll : Anchor {
  std::vector<bp::polygon_with_holes_data<I>> polys;
  explicit BoostAll(const IntFootprints& in) {
    for (const auto& f : in.fps) {
      // rings in order: an outer ring, then its holes (negative area)
      for (std::size_t k = 0; k < f.rings.size(); ++k) {
        if (area2(f.rings[k]) < 0) continue;
        auto pts = [](const IRing& r) {
          std::vector<bp::point_data<I>> v;
          v.reserve(r.size());
          for (const IPoint& q : r) v.emplace_back(q.x, q.y);
          return v;
        };
        bp::polygon_with_holes_data<I> p;
        const auto outer = pts(f.rings[k]);
        p.set(outer.begin(), outer.end());
        std::vector<bp::polygon_data<I>> holes;
        for (std::size_t h = k + 1; h < f.rings.size() && area2(f.rings[h]) < 0; ++h) {
          const auto hp = pts(f.rings[h]);
          holes.emplace_back(hp.begin(), hp.end());
        }
        p.set_holes(holes.begin(), holes.end());
        polys.push_back(std::move(p));
      }
    }
  }
  std::size_t run() override {
    bp::polygon_set_data<I> set;
    for (const auto& p : polys) set.insert(p);
    std::vector<bp::polygon_with_holes_data<I>> out;
    set.get(out);
    return out.size();
  }
};
#endif

}  // namespace

std::unique_ptr<Anchor> make_anchor(const std::string& name, const std::vector<Footprint>& footprints,
                                    std::string& why) {
#ifdef GROUNDPLAN_BENCH_CLIPPER2
  if (name == "clipper2") return std::make_unique<ClipperOne>(IntFootprints(footprints));
  if (name == "clipper2_groups") return std::make_unique<ClipperGroups>(IntFootprints(footprints));
#else
  if (name == "clipper2" || name == "clipper2_groups") {
    why = "Clipper2 not built in: tests/bench/union_anchors.sh configures GROUNDPLAN_BENCH_CLIPPER2_DIR";
    return nullptr;
  }
#endif
#ifdef GROUNDPLAN_BENCH_BOOST_POLYGON
  if (name == "boost") return std::make_unique<BoostAll>(IntFootprints(footprints));
#else
  if (name == "boost") {
    why = "Boost.Polygon not built in: install libboost-dev and configure again";
    return nullptr;
  }
#endif
  (void)footprints;
  why = "unknown anchor " + name;
  return nullptr;
}

}  // namespace groundplan::bench

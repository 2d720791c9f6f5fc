// SPDX-License-Identifier: MIT
// The union's shortcut for blocks whose rings neither touch nor cross (block_union.cpp, simple_rings()): it must
// give exactly what the walk and the completeness check give, bit for bit (rings, their start vertices and
// order, members, areas, problems), and it must be taken where it applies.
#include <gtest/gtest.h>

#include <groundplan/ground_plans.h>
#include <groundplan/raster_backend.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "union/block_union.h"
#include "union_generators.h"

namespace groundplan {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_ring(const Ring& a, const Ring& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_bits(a[i].x, b[i].x) || !same_bits(a[i].y, b[i].y)) return false;
  return true;
}

/// Unites `members` with and without the shortcut; fails the test where the results differ in any bit.
/// Returns whether the shortcut was taken.
bool expect_same(const std::vector<Footprint>& fps, const std::vector<std::uint32_t>& members, const std::string& what) {
  double m = 0;
  for (std::uint32_t fi : members)
    for (const Polygon& p : fps[fi].polygons) {
      for (const Point2& q : p.outer) m = std::max({m, std::fabs(q.x), std::fabs(q.y)});
      for (const Ring& h : p.holes)
        for (const Point2& q : h) m = std::max({m, std::fabs(q.x), std::fabs(q.y)});
    }
  const double pitch = snap_pitch(m);
  const detail::BlockResult fast = detail::union_block(fps, members, pitch, true);
  const detail::BlockResult slow = detail::union_block(fps, members, pitch, false);
  EXPECT_EQ(slow.stats.simple_rings, 0u) << what;
  EXPECT_EQ(fast.plans.size(), slow.plans.size()) << what;
  for (std::size_t k = 0; k < std::min(fast.plans.size(), slow.plans.size()); ++k) {
    const GroundPlan& a = fast.plans[k];
    const GroundPlan& b = slow.plans[k];
    EXPECT_TRUE(same_ring(a.polygon.outer, b.polygon.outer)) << what << ": plan " << k << " outer ring";
    EXPECT_EQ(a.polygon.holes.size(), b.polygon.holes.size()) << what << ": plan " << k;
    for (std::size_t h = 0; h < std::min(a.polygon.holes.size(), b.polygon.holes.size()); ++h)
      EXPECT_TRUE(same_ring(a.polygon.holes[h], b.polygon.holes[h])) << what << ": plan " << k << " hole " << h;
    EXPECT_EQ(a.members, b.members) << what << ": plan " << k;
    EXPECT_TRUE(same_bits(a.area_m2, b.area_m2)) << what << ": plan " << k;
  }
  EXPECT_EQ(fast.problems.size(), slow.problems.size()) << what;
  for (std::size_t k = 0; k < std::min(fast.problems.size(), slow.problems.size()); ++k)
    EXPECT_EQ(fast.problems[k].code, slow.problems[k].code) << what;
  EXPECT_EQ(fast.snapped, slow.snapped) << what;
  return fast.stats.simple_rings == 1;
}

std::vector<std::uint32_t> all_of(const std::vector<Footprint>& fps) {
  std::vector<std::uint32_t> m(fps.size());
  for (std::uint32_t i = 0; i < m.size(); ++i) m[i] = i;
  return m;
}

// A star-shaped ring around (cx, cy): vertices at radii in [r0, r1], angular gaps at most 60 degrees, so it
// holds the disc of radius 0.86 r0; optionally with exactly collinear (straight) vertices, reversed, rotated.
Ring star(testing::Rng& rng, double cx, double cy, double r0, double r1, bool ccw) {
  std::uniform_real_distribution<double> u(0, 1);
  const int n = 6 + static_cast<int>(u(rng) * 10);
  Ring r;
  for (int i = 0; i < n; ++i) {
    const double a = (i + 0.2 + 0.6 * u(rng)) * 2 * M_PI / n;
    const double rad = r0 + (r1 - r0) * u(rng);
    r.push_back({cx + rad * std::cos(a), cy + rad * std::sin(a)});
  }
  if (!ccw) std::reverse(r.begin(), r.end());
  std::rotate(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(u(rng) * n), r.end());
  return r;
}

// An axis-parallel rectangle on integers with straight vertices on its sides (exactly collinear).
Ring rect_with_straight_vertices(testing::Rng& rng, double x0, double y0, double w, double h, bool ccw) {
  std::uniform_int_distribution<int> k(0, 2);
  Ring r{{x0, y0}};
  for (int i = 0; i < k(rng); ++i) r.push_back({x0 + w * (i + 1) / 4, y0});
  r.push_back({x0 + w, y0});
  for (int i = 0; i < k(rng); ++i) r.push_back({x0 + w, y0 + h * (i + 1) / 4});
  r.push_back({x0 + w, y0 + h});
  r.push_back({x0, y0 + h});
  if (!ccw) std::reverse(r.begin(), r.end());
  std::rotate(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(k(rng) % r.size()), r.end());
  return r;
}

TEST(UnionShortcut, SameAsTheWalkOnDetachedBuildingsWithHolesAndIslands) {
  testing::Rng rng(39);
  std::uniform_real_distribution<double> u(0, 1);
  std::size_t taken = 0, cases = 0;
  for (int c = 0; c < 400; ++c) {
    std::vector<Footprint> fps;
    const double ox = c % 2 ? 512345.25 : 0, oy = c % 2 ? 5401234.5 : 0;  // city coordinates too
    const int n = c % 50 == 0 ? 30 : 1 + c % 5;  // some blocks of many polygons (the grid of polygons)
    std::vector<Footprint> extra;
    for (int i = 0; i < n; ++i) {
      Footprint f;
      f.source_id = std::to_string(i);
      const double cx = ox + 100.0 * i, cy = oy + (u(rng) < 0.5 ? 0 : 30);
      const int polys = u(rng) < 0.8 ? 1 : 2;  // a footprint of two polygons far apart
      for (int p = 0; p < polys; ++p) {
        Polygon poly;
        const double px = cx, py = cy + 45.0 * p;
        if (u(rng) < 0.3) {
          poly.outer = rect_with_straight_vertices(rng, std::floor(px), std::floor(py), 16, 12, u(rng) < 0.5);
          if (u(rng) < 0.5)  // an integer courtyard
            poly.holes.push_back(rect_with_straight_vertices(rng, std::floor(px) + 4, std::floor(py) + 4, 8, 4, u(rng) < 0.5));
        } else {
          poly.outer = star(rng, px, py, 12, 20, u(rng) < 0.5);
          if (u(rng) < 0.5) {
            poly.holes.push_back(star(rng, px, py, 5, 8, u(rng) < 0.5));      // a courtyard
            if (u(rng) < 0.5) {
              poly.holes.push_back(star(rng, px, py, 1, 3, u(rng) < 0.5));  // an island in it
            } else if (u(rng) < 0.5) {
              Footprint kiosk;  // another building in the courtyard: its ring is a boundary
              kiosk.polygons.push_back(Polygon{star(rng, px, py, 1, 2, u(rng) < 0.5), {}});
              extra.push_back(std::move(kiosk));
            }
          }
          if (u(rng) < 0.3) {
            Footprint inner;  // a building within this one's walls: covered, no boundary of its own
            inner.polygons.push_back(Polygon{star(rng, px + 10, py, 0.3, 0.9, u(rng) < 0.5), {}});
            extra.push_back(std::move(inner));
          }
        }
        f.polygons.push_back(std::move(poly));
      }
      fps.push_back(std::move(f));
    }
    for (Footprint& f : extra) fps.push_back(std::move(f));
    if (c % 3 == 1) {
      // row houses with a party wall on integers, left or right of the rest: a component the walk must take
      const double x = std::floor(ox) + (u(rng) < 0.5 ? -60.0 : 100.0 * n + 20), y = std::floor(oy);
      for (int k = 0; k < 2; ++k) {
        Footprint h;
        h.polygons.push_back(Polygon{{{x + 8 * k, y}, {x + 8 * k + 8, y}, {x + 8 * k + 8, y + 10}, {x + 8 * k, y + 10}}, {}});
        fps.push_back(std::move(h));
      }
    }
    const std::string what = "case " + std::to_string(c);
    taken += expect_same(fps, all_of(fps), what);
    ++cases;
    for (std::uint32_t i = 0; i < fps.size(); ++i) taken += expect_same(fps, {i}, what + " footprint " + std::to_string(i));
    cases += fps.size();
  }
  // every case has rings apart: the shortcut is taken on all of them (on some rings where row houses are in it)
  EXPECT_EQ(taken, cases);
}

TEST(UnionShortcut, SameAsTheWalkOnEveryFamilyAndTheCity) {
  // The property families are mostly touching and crossing rings (the shortcut must decline them, and where it
  // does not, give the same); the synthetic city's blocks are as build_ground_plans finds them.
  std::size_t taken = 0, blocks = 0;
  for (testing::Family f : testing::kAllFamilies) {
    testing::Rng rng(3900 + static_cast<int>(f));
    for (int c = 0; c < (f == testing::Family::DenseRings ? 5 : 60); ++c) {
      const auto fps = testing::generate_case(f, rng);
      const std::string what = std::string(testing::family_name(f)) + " case " + std::to_string(c);
      taken += expect_same(fps, all_of(fps), what);
      for (std::uint32_t i = 0; i < fps.size(); ++i) taken += expect_same(fps, {i}, what + " footprint " + std::to_string(i));
    }
  }
  const auto city = testing::synthetic_city(6000, 1);
  FootprintSet set = make_footprint_set(city);
  const std::vector<Block> bl = make_raster_backend(Device::Cpu)->find_blocks(set, make_pixel_grid(set, 0), Progress{});
  std::size_t city_taken = 0;
  for (const Block& b : bl) {
    city_taken += expect_same(city, b.footprints, "city block of footprint " + std::to_string(b.footprints[0]));
    ++blocks;
  }
  // the city's detached houses and lone buildings take it, its row houses (party walls) do not
  EXPECT_GT(city_taken, blocks / 10);
  EXPECT_LT(city_taken, blocks);
  EXPECT_GT(taken, 0u);
}

}  // namespace
}  // namespace groundplan

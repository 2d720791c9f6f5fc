// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5): synthetic buildings made in code, one hard
// case each, with known footprints compared through GEOS (symmetric difference, validity).
#include "footprint/decompose.h"

#include <groundplan/gis/geos_reference.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

namespace groundplan::footprint {
namespace {

using Ring3 = std::vector<Point3>;
using Ring2 = std::vector<Point2>;
using ZFn = std::function<double(double, double)>;

double ring_area(const Ring2& r) {
  double a = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Point2 &p = r[i], &q = r[(i + 1) % r.size()];
    a += p.x * q.y - q.x * p.y;
  }
  return a / 2;
}

Ring2 rect(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

/// A prism over `outer` (CCW) with `holes` (CW): walls from z_bottom(x, y) to z_top, a floor and a
/// roof when asked. Faces outward, as a clean closed solid would be written.
Mesh prism(const Ring2& outer, const std::vector<Ring2>& holes, const ZFn& zb, double z_top, bool floor, bool roof) {
  Mesh m;
  auto walls = [&](const Ring2& r) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Point2 &p = r[i], &q = r[(i + 1) % r.size()];
      m.add_face({{{p.x, p.y, zb(p.x, p.y)}, {q.x, q.y, zb(q.x, q.y)}, {q.x, q.y, z_top}, {p.x, p.y, z_top}}},
                 SurfaceKind::Wall, 2);
    }
  };
  walls(outer);
  for (const Ring2& h : holes) walls(h);
  auto lift = [](const Ring2& r, const std::function<double(double, double)>& z, bool reverse) {
    Ring3 out;
    for (const Point2& p : r) out.push_back({p.x, p.y, z(p.x, p.y)});
    if (reverse) std::reverse(out.begin(), out.end());
    return out;
  };
  if (roof) {
    std::vector<Ring3> rings{lift(outer, [&](double, double) { return z_top; }, false)};
    for (const Ring2& h : holes) rings.push_back(lift(h, [&](double, double) { return z_top; }, false));
    m.add_face(rings, SurfaceKind::Roof, 2);
  }
  if (floor) {
    std::vector<Ring3> rings{lift(outer, zb, true)};
    for (const Ring2& h : holes) rings.push_back(lift(h, zb, true));
    m.add_face(rings, SurfaceKind::Ground, 2);
  }
  return m;
}

ZFn flat(double z) {
  return [z](double, double) { return z; };
}

void append(Mesh& into, const Mesh& from) {
  for (const MeshFace& f : from.faces) {
    std::vector<Ring3> rings;
    for (std::uint32_t r = f.first_ring; r < f.first_ring + f.ring_count; ++r) {
      Ring3 ring;
      for (std::uint32_t k = from.ring_offsets[r]; k < from.ring_offsets[r + 1]; ++k) ring.push_back(from.vertices[from.indices[k]]);
      rings.push_back(ring);
    }
    into.add_face(rings, f.kind, f.lod);
  }
}

/// Every face's rings reversed where `flip(face)` says so.
Mesh reoriented(const Mesh& m, const std::function<bool(std::size_t)>& flip) {
  Mesh out;
  for (std::size_t i = 0; i < m.faces.size(); ++i) {
    const MeshFace& f = m.faces[i];
    std::vector<Ring3> rings;
    for (std::uint32_t r = f.first_ring; r < f.first_ring + f.ring_count; ++r) {
      Ring3 ring;
      for (std::uint32_t k = m.ring_offsets[r]; k < m.ring_offsets[r + 1]; ++k) ring.push_back(m.vertices[m.indices[k]]);
      if (flip(i)) std::reverse(ring.begin(), ring.end());
      rings.push_back(ring);
    }
    out.add_face(rings, f.kind, f.lod);
  }
  return out;
}

/// Triangle soup: convex faces without holes fanned into triangles, each triangle with its own
/// vertex copies jittered by up to `jitter`, triangles shuffled and randomly flipped (fixed seed).
Mesh soup(const Mesh& m, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> j(-jitter, jitter);
  std::vector<std::array<Point3, 3>> tris;
  for (const MeshFace& f : m.faces) {
    const std::uint32_t a = m.ring_offsets[f.first_ring], b = m.ring_offsets[f.first_ring + 1];
    for (std::uint32_t k = a + 1; k + 1 < b; ++k)
      tris.push_back({m.vertices[m.indices[a]], m.vertices[m.indices[k]], m.vertices[m.indices[k + 1]]});
  }
  std::shuffle(tris.begin(), tris.end(), rng);
  Mesh out;
  for (auto& t : tris) {
    if (rng() % 2) std::swap(t[1], t[2]);
    Ring3 ring;
    for (Point3 p : t) ring.push_back({p.x + j(rng), p.y + j(rng), p.z + j(rng)});
    out.add_face({ring}, SurfaceKind::Unknown, 255);
  }
  return out;
}

struct Check {
  double symdiff = 0, area = 0, expected_area = 0;
  std::size_t invalid = 0, polygons = 0, holes = 0;
};

/// Our polygons against the expected WKT: symmetric difference (GEOS) and validity of each polygon.
/// Several expected WKTs are unioned (they may overlap).
Check compare(const DecomposeResult& res, const std::string& expected_wkt, const std::vector<std::string>& more = {}) {
  Footprint ref;
  ref.polygons = gis::polygons_from_wkt(expected_wkt);
  for (const std::string& w : more)
    for (Polygon& p : gis::polygons_from_wkt(w)) ref.polygons.push_back(std::move(p));
  std::vector<GroundPlan> ours;
  Check c;
  for (const Polygon& p : res.polygons) {
    ours.push_back(GroundPlan{p, {}, 0});
    c.holes += p.holes.size();
    for (const Point2& q : p.outer) EXPECT_TRUE(std::isfinite(q.x) && std::isfinite(q.y));
    EXPECT_GT(ring_area(p.outer), 0) << "outer rings are counter-clockwise";
    for (const Ring2& h : p.holes) EXPECT_LT(ring_area(h), 0) << "holes are clockwise";
  }
  const gis::GeosComparison g = gis::compare_with_geos({ref}, ours);
  c.symdiff = g.symdiff_area;
  c.area = g.area_ours;
  c.expected_area = g.area_geos;
  c.invalid = g.invalid_ours;
  c.polygons = res.polygons.size();
  return c;
}

constexpr double kEps = 1e-6;
const char* kSquare = "POLYGON((0 0,10 0,10 10,0 10,0 0))";
const char* kCourtyard = "POLYGON((0 0,20 0,20 20,0 20,0 0),(6 6,6 14,14 14,14 6,6 6))";

Mesh courtyard(bool floor, bool roof, const ZFn& zb = flat(0), double z_top = 9) {
  return prism(rect(0, 0, 20, 20), {{{6, 6}, {6, 14}, {14, 14}, {14, 6}}}, zb, z_top, floor, roof);
}

TEST(DecomposeFootprint, ClosedBox) {
  const DecomposeResult r = decompose_footprint(prism(rect(0, 0, 10, 10), {}, flat(0), 6, true, true));
  const Check c = compare(r, kSquare);
  EXPECT_EQ(c.polygons, 1u);
  EXPECT_LT(c.symdiff, kEps);
  EXPECT_EQ(c.invalid, 0u);
  EXPECT_EQ(r.stats.open_chains, 0u);
}

TEST(DecomposeFootprint, Decomposition) {
  SurfaceDecomposition d;
  decompose_footprint(prism(rect(0, 0, 10, 10), {}, flat(2), 6, true, true), {}, &d);
  ASSERT_EQ(d.patch_kind.size(), 3u);
  // Bottom-up: the floor (z 2) and the walls start lowest, the roof last.
  EXPECT_EQ(std::count(d.patch_kind.begin(), d.patch_kind.end(), PatchKind::Floor), 1);
  EXPECT_EQ(std::count(d.patch_kind.begin(), d.patch_kind.end(), PatchKind::Wall), 1);
  EXPECT_EQ(d.patch_kind.back(), PatchKind::Ceiling);
  EXPECT_NEAR(d.patch_z.back(), 6, 1e-12);
  EXPECT_NEAR(d.patch_area_m2.back(), 100, 1e-9);
  for (std::size_t p = 0; p < d.patch_kind.size(); ++p)
    if (d.patch_kind[p] == PatchKind::Floor) {
      EXPECT_NEAR(d.patch_z[p], 2, 1e-12);
    }
}

TEST(DecomposeFootprint, OpenBottom) {
  const DecomposeResult r = decompose_footprint(prism(rect(0, 0, 10, 10), {}, flat(0), 6, false, true));
  const Check c = compare(r, kSquare);
  EXPECT_EQ(c.polygons, 1u);
  EXPECT_LT(c.symdiff, kEps);
}

TEST(DecomposeFootprint, OpenBottomAndTop) {
  // Four walls only: still a volume about the low point, still one way out.
  const DecomposeResult r = decompose_footprint(prism(rect(0, 0, 10, 10), {}, flat(0), 6, false, false));
  EXPECT_LT(compare(r, kSquare).symdiff, kEps);
}

TEST(DecomposeFootprint, FloorWithHole) {
  // The floor has an opening (a stair well to a basement, a missing polygon): the walls still say
  // where the building stands, so the footprint is the whole square.
  Mesh m = prism(rect(0, 0, 10, 10), {}, flat(0), 6, false, true);
  m.add_face({{{0, 0, 0}, {0, 10, 0}, {10, 10, 0}, {10, 0, 0}}, {{3, 3, 0}, {7, 3, 0}, {7, 7, 0}, {3, 7, 0}}},
             SurfaceKind::Unknown, 2);
  const Check c = compare(decompose_footprint(m), kSquare);
  EXPECT_EQ(c.holes, 0u);
  EXPECT_LT(c.symdiff, kEps);
}

TEST(DecomposeFootprint, Courtyard) {
  for (bool floor : {false, true}) {
    const DecomposeResult r = decompose_footprint(courtyard(floor, true));
    const Check c = compare(r, kCourtyard);
    EXPECT_EQ(c.polygons, 1u);
    EXPECT_EQ(c.holes, 1u);
    EXPECT_LT(c.symdiff, kEps) << "floor " << floor;
    EXPECT_EQ(c.invalid, 0u);
  }
}

TEST(DecomposeFootprint, InconsistentOrientation) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    std::mt19937 rng(seed);
    const Mesh m = reoriented(courtyard(false, true), [&](std::size_t) { return rng() % 2 == 1; });
    const DecomposeResult r = decompose_footprint(m);
    const Check c = compare(r, kCourtyard);
    EXPECT_EQ(c.holes, 1u) << "seed " << seed;
    EXPECT_LT(c.symdiff, kEps) << "seed " << seed;
  }
  // All faces inward (a shell written inside out).
  const DecomposeResult r = decompose_footprint(reoriented(courtyard(true, true), [](std::size_t) { return true; }));
  EXPECT_LT(compare(r, kCourtyard).symdiff, kEps);
}

TEST(DecomposeFootprint, DuplicatedVerticesWithinTolerance) {
  // Every face has its own corner copies (as readers deliver them), moved by up to 0.3 mm.
  Mesh m = courtyard(false, true);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> j(-3e-4, 3e-4);
  for (Point3& p : m.vertices) p = {p.x + j(rng), p.y + j(rng), p.z + j(rng)};
  const DecomposeResult r = decompose_footprint(m);
  EXPECT_LT(compare(r, kCourtyard).symdiff, 0.05);  // area moves by jitter x perimeter at most
  EXPECT_EQ(r.stats.open_chains, 0u);
  EXPECT_EQ(r.stats.vertices_welded, 16u);  // 8 corners at two heights
}

TEST(DecomposeFootprint, TriangleSoup) {
  // The courtyard roof and floor as convex quads (corner frame), then all of it triangle soup.
  Mesh quads = prism(rect(0, 0, 20, 20), {{{6, 6}, {6, 14}, {14, 14}, {14, 6}}}, flat(0), 9, false, false);
  const Ring2 o = rect(0, 0, 20, 20), h = rect(6, 6, 14, 14);
  for (std::size_t i = 0; i < 4; ++i) {
    const Point2 &a = o[i], &b = o[(i + 1) % 4], &c = h[(i + 1) % 4], &d = h[i];
    quads.add_face({{{a.x, a.y, 9}, {b.x, b.y, 9}, {c.x, c.y, 9}, {d.x, d.y, 9}}}, SurfaceKind::Unknown, 255);
    quads.add_face({{{d.x, d.y, 0}, {c.x, c.y, 0}, {b.x, b.y, 0}, {a.x, a.y, 0}}}, SurfaceKind::Unknown, 255);
  }
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const DecomposeResult r = decompose_footprint(soup(quads, 2e-4, seed));
    const Check c = compare(r, kCourtyard);
    EXPECT_EQ(c.polygons, 1u) << "seed " << seed;
    EXPECT_EQ(c.holes, 1u) << "seed " << seed;
    EXPECT_LT(c.symdiff, 0.05) << "seed " << seed;
    EXPECT_EQ(c.invalid, 0u) << "seed " << seed;
  }
  // Without welding (tolerance below the jitter) nothing connects: no loop, and no garbage. The
  // shadow fallback (rule 3) still finds the courtyard from the roof triangles alone.
  DecomposeParams p;
  p.weld_tolerance_m = 1e-9;
  const DecomposeResult unwelded = decompose_footprint(soup(quads, 2e-4, 1), p);
  EXPECT_TRUE(unwelded.stats.shadow);
  EXPECT_EQ(unwelded.stats.loops, 0u);
  EXPECT_LT(compare(unwelded, kCourtyard).symdiff, 0.05);
  p.shadow_fallback = false;
  EXPECT_TRUE(decompose_footprint(soup(quads, 2e-4, 1), p).polygons.empty());
}

TEST(DecomposeFootprint, SlopingTerrain) {
  // Walls end on a sloping ground (lowest wall edge not at one height), with and without a floor
  // following the slope (30 % = 16.7 degrees, inside the default proxy tolerance).
  const ZFn slope = [](double x, double y) { return 100 + 0.3 * x + 0.05 * y; };
  for (bool floor : {false, true}) {
    const DecomposeResult r = decompose_footprint(courtyard(floor, true, slope));
    const Check c = compare(r, kCourtyard);
    EXPECT_EQ(c.holes, 1u) << "floor " << floor;
    EXPECT_LT(c.symdiff, kEps) << "floor " << floor;
  }
  // A steep 60 % slope: fine with an open bottom; with a floor that steep the proxy tolerance must
  // be raised, or the floor counts as a wall.
  const ZFn steep = [](double x, double) { return 0.6 * x; };
  EXPECT_LT(compare(decompose_footprint(courtyard(false, true, steep, 30)), kCourtyard).symdiff, kEps);
  DecomposeParams hilly;
  hilly.proxy_tolerance_deg = 35;
  EXPECT_LT(compare(decompose_footprint(courtyard(true, true, steep, 30), hilly), kCourtyard).symdiff, kEps);
}

/// Ground floor [0,10]x[0,10] (z 0..3), upper storey [0,14]x[0,10] (z 3..6) cantilevered over x 10..14.
/// `split`: walls written per storey, so the upper walls' bottom edges meet the soffit and the lower
/// walls in T-junctions.
Mesh overhang(bool floor, bool split) {
  Mesh m;
  if (split) {
    m.add_face({{{0, 0, 0}, {10, 0, 0}, {10, 0, 3}, {0, 0, 3}}}, SurfaceKind::Wall, 2);
    m.add_face({{{0, 0, 3}, {14, 0, 3}, {14, 0, 6}, {0, 0, 6}}}, SurfaceKind::Wall, 2);
    m.add_face({{{10, 10, 0}, {0, 10, 0}, {0, 10, 3}, {10, 10, 3}}}, SurfaceKind::Wall, 2);
    m.add_face({{{14, 10, 3}, {0, 10, 3}, {0, 10, 6}, {14, 10, 6}}}, SurfaceKind::Wall, 2);
  } else {
    m.add_face({{{0, 0, 0}, {10, 0, 0}, {10, 0, 3}, {14, 0, 3}, {14, 0, 6}, {0, 0, 6}}}, SurfaceKind::Wall, 2);
    m.add_face({{{14, 10, 6}, {14, 10, 3}, {10, 10, 3}, {10, 10, 0}, {0, 10, 0}, {0, 10, 6}}}, SurfaceKind::Wall, 2);
  }
  m.add_face({{{0, 10, 0}, {0, 0, 0}, {0, 0, 6}, {0, 10, 6}}}, SurfaceKind::Wall, 2);        // x = 0
  m.add_face({{{10, 0, 0}, {10, 10, 0}, {10, 10, 3}, {10, 0, 3}}}, SurfaceKind::Wall, 2);    // x = 10, below
  m.add_face({{{14, 0, 3}, {14, 10, 3}, {14, 10, 6}, {14, 0, 6}}}, SurfaceKind::Wall, 2);    // x = 14, above
  m.add_face({{{10, 0, 3}, {10, 10, 3}, {14, 10, 3}, {14, 0, 3}}}, SurfaceKind::Other, 2);   // soffit, down
  m.add_face({{{0, 0, 6}, {14, 0, 6}, {14, 10, 6}, {0, 10, 6}}}, SurfaceKind::Roof, 2);
  if (floor) m.add_face({{{0, 0, 0}, {0, 10, 0}, {10, 10, 0}, {10, 0, 0}}}, SurfaceKind::Ground, 2);
  return m;
}

TEST(DecomposeFootprint, OverhangIsNotTheShadow) {
  for (bool floor : {false, true})
    for (bool split : {false, true}) {
      SurfaceDecomposition d;
      const DecomposeResult r = decompose_footprint(overhang(floor, split), {}, &d);
      const Check c = compare(r, kSquare);
      EXPECT_EQ(c.polygons, 1u) << floor << split;
      EXPECT_LT(c.symdiff, kEps) << "floor " << floor << " split " << split << ": area " << c.area;
      EXPECT_EQ(std::count(d.patch_kind.begin(), d.patch_kind.end(), PatchKind::Floor), floor ? 2 : 1);
      if (split) {
        EXPECT_GT(r.stats.t_junction_splits, 0u);
      }
    }
}

TEST(DecomposeFootprint, UpperStoreyWiderOnEverySide) {
  // Ground storey [4,16]^2 (z 0..3), upper storey [0,20]^2 (z 3..8) overhanging on all sides: the
  // upper walls' foot closes into a loop around the soffit, but the soffit hangs (walls go down from
  // its inner edge), so the footprint is the ground storey, not the shadow.
  for (bool floor : {false, true}) {
    Mesh m = prism(rect(4, 4, 16, 16), {}, flat(0), 3, floor, false);
    append(m, prism(rect(0, 0, 20, 20), {}, flat(3), 8, false, true));
    m.add_face({{{0, 0, 3}, {0, 20, 3}, {20, 20, 3}, {20, 0, 3}}, {{4, 4, 3}, {16, 4, 3}, {16, 16, 3}, {4, 16, 3}}},
               SurfaceKind::Other, 2);  // soffit, facing down
    const DecomposeResult r = decompose_footprint(m);
    const Check c = compare(r, "POLYGON((4 4,16 4,16 16,4 16,4 4))");
    EXPECT_LT(c.symdiff, kEps) << "floor " << floor << ": area " << c.area;
  }
}

TEST(DecomposeFootprint, PartOnHigherGroundBesideATallerOneKeepsItsFootprint) {
  // Two closed parts side by side (issue 21, contacts.cpp rule c): B stands 0.5 m higher than A and
  // rises 7.5 m, so its floor's west edge lies in A's east wall, which goes on below it. That is how a
  // balcony slab leans on a wall too, but B stands lower above A's bottom than it is tall: its floor
  // is ground and the footprint is both parts. A slab 0.2 m thick at the same place hangs.
  for (const double top : {8.0, 0.7}) {
    Mesh m = prism(rect(0, 0, 10, 10), {}, flat(0), 10, true, true);
    append(m, prism(rect(10, 2, 14, 8), {}, flat(0.5), top, true, true));
    const DecomposeResult r = decompose_footprint(m);
    const Check c = compare(r, top > 1 ? "POLYGON((0 0,10 0,10 2,14 2,14 8,10 8,10 10,0 10,0 0))" : kSquare);
    EXPECT_LT(c.symdiff, kEps) << "top " << top << ": area " << c.area;
    EXPECT_FALSE(r.stats.shadow) << top;
  }
}

TEST(DecomposeFootprint, DisconnectedParts) {
  Mesh m = prism(rect(0, 0, 10, 10), {}, flat(0), 6, true, true);
  append(m, prism(rect(30, 0, 40, 5), {}, flat(12), 20, false, true));
  append(m, courtyard(false, true, flat(-3)));  // overlaps the first: united in the footprint (issue 21)
  const DecomposeResult r = decompose_footprint(m);
  EXPECT_EQ(r.polygons.size(), 2u);  // the box and the courtyard one polygon, the far box the other
  EXPECT_TRUE(r.stats.united);
  EXPECT_EQ(r.stats.components, 3u);
  const Check c = compare(r, kSquare, {kCourtyard, "POLYGON((30 0,40 0,40 5,30 5,30 0))"});
  EXPECT_LT(c.symdiff, kEps);
}

TEST(DecomposeFootprint, NonManifoldCornerContact) {
  // Two boxes meeting along one vertical edge: four facets on that edge, two ways on at its foot.
  Mesh m = prism(rect(0, 0, 1, 1), {}, flat(0), 3, true, true);
  append(m, prism(rect(1, 1, 2, 2), {}, flat(0), 3, true, true));
  const DecomposeResult r = decompose_footprint(m);
  EXPECT_GT(r.stats.nonmanifold_edges, 0u);
  const Check c = compare(r, "MULTIPOLYGON(((0 0,1 0,1 1,0 1,0 0)),((1 1,2 1,2 2,1 2,1 1)))");
  EXPECT_EQ(c.polygons, 2u);  // two simple rings touching at a point, not one figure-eight
  EXPECT_EQ(c.invalid, 0u);
  EXPECT_LT(c.symdiff, kEps);
}

TEST(DecomposeFootprint, NonManifoldSharedWall) {
  // Two closed boxes sharing a wall (each with its own copy): the shared wall's foot is no footprint
  // edge (it rises on both sides), the footprint is the union.
  Mesh m = prism(rect(0, 0, 1, 1), {}, flat(0), 3, true, true);
  append(m, prism(rect(1, 0, 2, 1), {}, flat(0), 3, true, true));
  const DecomposeResult r = decompose_footprint(m);
  const Check c = compare(r, "POLYGON((0 0,2 0,2 1,0 1,0 0))");
  EXPECT_LT(c.symdiff, kEps);
  EXPECT_EQ(c.invalid, 0u);
  // The second box's copy of the shared wall as two triangles: not a duplicate face, so the two
  // walls rising from the shared foot on opposite sides must cancel there.
  Mesh t = prism(rect(0, 0, 1, 1), {}, flat(0), 3, true, true);
  const Mesh b = prism(rect(1, 0, 2, 1), {}, flat(0), 3, true, true);
  for (std::size_t i = 0; i < b.faces.size(); ++i) {
    Ring3 ring;
    for (std::uint32_t k = b.ring_offsets[b.faces[i].first_ring]; k < b.ring_offsets[b.faces[i].first_ring + 1]; ++k)
      ring.push_back(b.vertices[b.indices[k]]);
    if (i == 3) {  // the x = 1 wall of the prism over rect(1, 0, 2, 1)
      t.add_face({{ring[0], ring[1], ring[2]}}, SurfaceKind::Wall, 2);
      t.add_face({{ring[0], ring[2], ring[3]}}, SurfaceKind::Wall, 2);
    } else {
      t.add_face({ring}, b.faces[i].kind, 2);
    }
  }
  const DecomposeResult rt = decompose_footprint(t);
  EXPECT_EQ(rt.stats.duplicate_faces, 0u);
  EXPECT_LT(compare(rt, "POLYGON((0 0,2 0,2 1,0 1,0 0))").symdiff, kEps);
}

TEST(DecomposeFootprint, FaceWrittenTwice) {
  // A wall written twice the same way (v2_Building_and_garage_LOD2: the garage's west wall), and
  // one written three times: the copies go, the box stays closed and oriented.
  for (int copies : {1, 2}) {
    const Mesh box = prism(rect(0, 0, 10, 10), {}, flat(0), 6, false, true);
    Mesh m = box;
    for (int c = 0; c < copies; ++c) append(m, box);
    const DecomposeResult r = decompose_footprint(m);
    EXPECT_EQ(r.stats.duplicate_faces, 5u * copies);
    EXPECT_EQ(r.stats.nonmanifold_edges, 0u);
    EXPECT_LT(compare(r, kSquare).symdiff, kEps);
  }
  Mesh m = prism(rect(0, 0, 10, 10), {}, flat(0), 6, false, true);
  m.add_face({{{0, 10, 0}, {0, 0, 0}, {0, 0, 6}, {0, 10, 6}}}, SurfaceKind::Wall, 2);
  const DecomposeResult r = decompose_footprint(m);
  EXPECT_EQ(r.stats.duplicate_faces, 1u);
  EXPECT_LT(compare(r, kSquare).symdiff, kEps);
}

TEST(DecomposeFootprint, ParapetIsNotAFootprint) {
  // A flat roof (z 6) inside a 1 m parapet: the parapet's inner walls rise from the roof, a closed
  // loop of walls with higher neighbours, but a ceiling boundary (paper §4), not a footprint.
  Mesh m = prism(rect(0, 0, 10, 10), {}, flat(0), 7, false, false);
  append(m, reoriented(prism(rect(1, 1, 9, 9), {}, flat(6), 7, false, false), [](std::size_t) { return true; }));
  m.add_face({{{0, 0, 7}, {10, 0, 7}, {10, 10, 7}, {0, 10, 7}}, {{1, 1, 7}, {1, 9, 7}, {9, 9, 7}, {9, 1, 7}}},
             SurfaceKind::Roof, 2);                                                            // parapet top
  m.add_face({{{1, 1, 6}, {9, 1, 6}, {9, 9, 6}, {1, 9, 6}}}, SurfaceKind::Roof, 2);            // the roof
  const DecomposeResult r = decompose_footprint(m);
  const Check c = compare(r, kSquare);
  EXPECT_EQ(c.holes, 0u);
  EXPECT_LT(c.symdiff, kEps);
}

TEST(DecomposeFootprint, DegenerateInput) {
  Mesh empty;
  EXPECT_TRUE(decompose_footprint(empty).polygons.empty());
  Mesh m = prism(rect(0, 0, 10, 10), {}, flat(0), 6, false, true);
  m.add_face({{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}}, SurfaceKind::Unknown, 2);                       // a point
  m.add_face({{{0, 0, 0}, {5, 5, 0}, {10, 10, 0}}}, SurfaceKind::Unknown, 2);                     // a line
  m.add_face({{{0, 0, NAN}, {5, 0, 0}, {5, 5, 0}}}, SurfaceKind::Unknown, 2);                     // NaN
  m.add_face({{{0, 0, 0}, {10, 0, 0}}}, SurfaceKind::Unknown, 2);                                 // 2 points
  m.add_face({{{0, 0, 0}, {0, 10, 0}, {10, 10, 0}, {10, 0, 0}}}, SurfaceKind::FootPrint, 0);      // lod0: skipped
  const DecomposeResult r = decompose_footprint(m);
  EXPECT_LT(compare(r, kSquare).symdiff, kEps);
  // A single wall has no inside and no closed lower boundary.
  Mesh wall;
  wall.add_face({{{0, 0, 0}, {10, 0, 0}, {10, 0, 3}, {0, 0, 3}}}, SurfaceKind::Unknown, 2);
  EXPECT_TRUE(decompose_footprint(wall).polygons.empty());
}

TEST(DecomposeFootprint, LargeCoordinates) {
  // UTM-sized coordinates: welding and areas relative to a local origin keep their digits.
  Mesh m = courtyard(false, true, flat(35));
  for (Point3& p : m.vertices) p = {p.x + 389'000.25, p.y + 5'819'000.5, p.z};
  const DecomposeResult r = decompose_footprint(m);
  ASSERT_EQ(r.polygons.size(), 1u);
  double a = ring_area(r.polygons[0].outer);
  for (const Ring2& h : r.polygons[0].holes) a += ring_area(h);
  EXPECT_NEAR(a, 400 - 64, 1e-6);
}

// ---- Rules beyond the paper (issue 5, Macky Auditorium) -------------------------------------------

/// A wall as one polygon in the vertical plane through a -> b (seen from outside: a on the left),
/// bottom given as (distance along a->b, z) points from a to b, top at z_top.
Ring3 wall(Point2 a, Point2 b, const std::vector<std::pair<double, double>>& bottom, double z_top) {
  const double len = std::hypot(b.x - a.x, b.y - a.y);
  auto at = [&](double s, double z) { return Point3{a.x + (b.x - a.x) * s / len, a.y + (b.y - a.y) * s / len, z}; };
  Ring3 r;
  for (auto [s, z] : bottom) r.push_back(at(s, z));
  r.push_back(at(bottom.back().first, z_top));
  r.push_back(at(bottom.front().first, z_top));
  return r;
}

void add_roof(Mesh& m, const Ring2& outer, double z) {
  Ring3 r;
  for (const Point2& p : outer) r.push_back({p.x, p.y, z});
  m.add_face({r}, SurfaceKind::Roof, 2);
}

TEST(DecomposeFootprint, BottomSteppingAtAVerticalEdgeClosesInPlan) {
  // Rule 2. A terraced site without floor: ground at z 0 for x < 5, z 1 beyond; the long walls step up
  // at x = 5 along a vertical edge. In 3D the lower boundary is two open chains; in plan it is the
  // square. Without the shadow fallback, so that only rule 2 can give it.
  Mesh m;
  m.add_face({wall({0, 0}, {10, 0}, {{0, 0}, {5, 0}, {5, 1}, {10, 1}}, 6)}, SurfaceKind::Wall, 2);
  m.add_face({wall({10, 0}, {10, 10}, {{0, 1}, {10, 1}}, 6)}, SurfaceKind::Wall, 2);
  m.add_face({wall({10, 10}, {0, 10}, {{0, 1}, {5, 1}, {5, 0}, {10, 0}}, 6)}, SurfaceKind::Wall, 2);
  m.add_face({wall({0, 10}, {0, 0}, {{0, 0}, {10, 0}}, 6)}, SurfaceKind::Wall, 2);
  add_roof(m, rect(0, 0, 10, 10), 6);
  DecomposeParams p;
  p.shadow_fallback = false;
  const DecomposeResult r = decompose_footprint(m, p);
  const Check c = compare(r, kSquare);
  EXPECT_EQ(c.polygons, 1u);
  EXPECT_LT(c.symdiff, kEps);
  EXPECT_EQ(c.invalid, 0u);
  EXPECT_EQ(r.stats.chained_in_plan, 1u);
  EXPECT_EQ(r.stats.open_chains, 0u);
  EXPECT_FALSE(r.stats.shadow);
}

/// A size x size x 6 box as SketchUp exports often come: each wall a separate quad stopping `gap` short
/// of the corners, a roof over all of it, no floor. Nothing connects the walls' bottoms.
Mesh gappy_box(double x0, double y0, double size, double gap) {
  Mesh m;
  const Ring2 o = rect(x0, y0, x0 + size, y0 + size);
  for (std::size_t i = 0; i < 4; ++i)
    m.add_face({wall(o[i], o[(i + 1) % 4], {{gap, 0}, {size - gap, 0}}, 6)}, SurfaceKind::Unknown, 255);
  add_roof(m, o, 6);
  return m;
}

TEST(DecomposeFootprint, LowerBoundaryWithGapsFallsBackToTheShadow) {
  // Rule 3. The walls' bottoms are four open chains, 30 cm apart at the corners: no loop, in 3D or in
  // plan (stage 7c joins ends within 10 cm). The footprint is the shadow: the roof's square.
  // (The gaps were 5 cm until stage 7c: those close in plan now, below.)
  const Mesh m = gappy_box(0, 0, 10, 0.3);
  const DecomposeResult r = decompose_footprint(m);
  const Check c = compare(r, kSquare);
  EXPECT_TRUE(r.stats.shadow);
  EXPECT_EQ(r.stats.loops, 0u);
  EXPECT_EQ(r.stats.open_chains, 4u);
  EXPECT_EQ(c.polygons, 1u);
  EXPECT_LT(c.symdiff, kEps);
  EXPECT_EQ(c.invalid, 0u);
  // Without the fallback: nothing, as before.
  DecomposeParams p;
  p.shadow_fallback = false;
  EXPECT_TRUE(decompose_footprint(m, p).polygons.empty());
  // A closed shed beside it closes a loop, but most of the lower boundary still lies in open chains
  // outside every loop: the loops miss the building, so the shadow of both.
  Mesh with_shed = m;
  append(with_shed, prism(rect(20, 0, 22, 2), {}, flat(0), 3, true, true));
  const DecomposeResult s = decompose_footprint(with_shed);
  EXPECT_TRUE(s.stats.shadow);
  EXPECT_LT(compare(s, kSquare, {"POLYGON((20 0,22 0,22 2,20 2,20 0))"}).symdiff, kEps);
  // Stage 7c: 5 cm gaps (ends 7 cm apart) close in plan at the corners the walls' lines meet in: the
  // walls' square, exactly, not the shadow; with the shed, both.
  Mesh near = gappy_box(0, 0, 10, 0.05);
  const DecomposeResult n = decompose_footprint(near);
  EXPECT_FALSE(n.stats.shadow);
  EXPECT_TRUE(n.stats.closed_in_plan);
  EXPECT_LT(compare(n, kSquare).symdiff, kEps);
  append(near, prism(rect(20, 0, 22, 2), {}, flat(0), 3, true, true));
  const DecomposeResult ns = decompose_footprint(near);
  EXPECT_TRUE(ns.stats.closed_in_plan);
  EXPECT_LT(compare(ns, kSquare, {"POLYGON((20 0,22 0,22 2,20 2,20 0))"}).symdiff, kEps);
}

TEST(DecomposeFootprint, CourtyardClosedInPlanKeepsItsHole) {
  // Stage 7c: a courtyard building whose outer and inner walls all stop 5 cm short of the corners.
  // The inner ring's face is open ground (its walls face into it): a hole, not building.
  Mesh m;
  auto gappy_ring = [&](const Ring2& o) {
    for (std::size_t i = 0; i < o.size(); ++i) {
      const Point2 &a = o[i], &b = o[(i + 1) % o.size()];
      const double len = std::hypot(b.x - a.x, b.y - a.y);
      m.add_face({wall(a, b, {{0.05, 0}, {len - 0.05, 0}}, 9)}, SurfaceKind::Unknown, 255);
    }
  };
  gappy_ring(rect(0, 0, 20, 20));
  gappy_ring({{6, 6}, {6, 14}, {14, 14}, {14, 6}});  // clockwise: the walls face the courtyard
  const DecomposeResult r = decompose_footprint(m);
  EXPECT_TRUE(r.stats.closed_in_plan);
  const Check c = compare(r, kCourtyard);
  EXPECT_EQ(c.holes, 1u);
  EXPECT_LT(c.symdiff, kEps);
}

TEST(DecomposeFootprint, OpenChainsInsideTheLoopsKeepTheLoops) {
  // Rule 3's condition. The cantilevered storey (footprint 10 x 10, shadow 14 x 10) carries a gappy
  // roof box standing on its roof, sharing no edge with it: the box's wall bottoms are open chains, but
  // inside the closed ground loop, so the loop stands and the overhang stays out. The box floats 0.5 m
  // above the roof: laid on it, its wall bottoms would stand on the roof (issue 21, contacts.cpp) and
  // be no lower boundary at all, which KnownFootprints (stacked_boxes) checks.
  Mesh m = overhang(false, false);
  Mesh top = gappy_box(2, 2, 6, 0.05);
  for (Point3& q : top.vertices) q.z += 6.5;
  append(m, top);
  const DecomposeResult r = decompose_footprint(m);
  const Check c = compare(r, kSquare);
  EXPECT_FALSE(r.stats.shadow);
  EXPECT_EQ(r.stats.open_chains, 4u);
  EXPECT_LT(c.symdiff, kEps);
}

TEST(DecomposeFootprint, OpenChainsAboveTheLoopsKeepTheLoops) {
  // Rule 3's condition, the other half. A closed box with a gappy bay (3 x 3 m, from z 3) hung on its
  // side, outside the ground loop but above it: a balcony is no ground, so no shadow.
  Mesh m = prism(rect(0, 0, 10, 10), {}, flat(0), 6, true, true);
  Mesh bay = gappy_box(10, 2, 3, 0.05);
  for (Point3& q : bay.vertices) q.z += 3;
  append(m, bay);
  const DecomposeResult r = decompose_footprint(m);
  EXPECT_FALSE(r.stats.shadow);
  EXPECT_GE(r.stats.open_chains, 1u);
  EXPECT_LT(compare(r, kSquare).symdiff, kEps);
}

}  // namespace
}  // namespace groundplan::footprint

// SPDX-License-Identifier: MIT
// Explicit footprints (issue 6): GroundSurface, lod0FootPrint, solid bottom; orientation; reasons.
#include <groundplan/footprint.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace groundplan {
namespace {

using Rings = std::vector<std::vector<Point3>>;

double area(const Ring& r) {
  double a = 0;
  for (std::size_t k = 0; k < r.size(); ++k) {
    const Point2& p = r[k];
    const Point2& q = r[(k + 1) % r.size()];
    a += p.x * q.y - q.x * p.y;
  }
  return a / 2;
}

double total_area(const Footprint& fp) {
  double a = 0;
  for (const Polygon& p : fp.polygons) {
    a += std::fabs(area(p.outer));
    for (const Ring& h : p.holes) a -= std::fabs(area(h));
  }
  return a;
}

/// An axis-aligned box [x0,x1]x[y0,y1]x[z0,z1] as 6 faces, outward (counter-clockwise seen from outside)
/// unless `inward`.
void add_box(Mesh& m, double x0, double y0, double z0, double x1, double y1, double z1, bool inward = false,
             SurfaceKind bottom_kind = SurfaceKind::Unknown, std::uint8_t lod = 1) {
  std::vector<Rings> faces = {
      {{{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}}},  // bottom, normal -z
      {{{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}},  // top, +z
      {{{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}},  // south, -y
      {{{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}}},  // east, +x
      {{{x1, y1, z0}, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}}},  // north, +y
      {{{x0, y1, z0}, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}}},  // west, -x
  };
  for (std::size_t i = 0; i < faces.size(); ++i) {
    Rings r = faces[i];
    if (inward) std::reverse(r[0].begin() + 1, r[0].end());
    m.add_face(r, i == 0 ? bottom_kind : SurfaceKind::Unknown, lod);
  }
}

TEST(ExplicitFootprint, BottomOfAnLod1Solid) {
  for (bool inward : {false, true}) {
    Mesh m;
    m.source_id = "box";
    m.source_file = "f.gml";
    add_box(m, 100, 200, 10, 112, 210, 20, inward);
    FootprintResult r = make_footprint(m);
    ASSERT_TRUE(r.ok) << r.reason;
    EXPECT_EQ(r.method, FootprintMethod::SolidBottom);
    ASSERT_EQ(r.footprint.polygons.size(), 1u);
    EXPECT_NEAR(total_area(r.footprint), 120, 1e-9);
    EXPECT_EQ(r.footprint.source_id, "box");
    EXPECT_EQ(r.footprint.source_file, "f.gml");
    EXPECT_EQ(r.footprint.min_z, 10);
    EXPECT_EQ(r.footprint.max_z, 20);
  }
}

TEST(ExplicitFootprint, OverhangUnderSideIsNotFootprint) {
  // A 10x10 block on the ground and an overhanging slab whose underside (facing down) is at z = 5.
  Mesh m;
  add_box(m, 0, 0, 0, 10, 10, 10);
  add_box(m, 10, 0, 5, 14, 10, 10);
  FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.footprint.polygons.size(), 1u);
  EXPECT_NEAR(total_area(r.footprint), 100, 1e-9);
  // A 45-degree undercut at the foot of a wall faces down and is low enough, but is not horizontal.
  m.add_face({{{0, 0, 0}, {10, 0, 0}, {10, -0.4, 0.4}, {0, -0.4, 0.4}}}, SurfaceKind::Unknown, 1);  // faces down and out
  r = make_footprint(m);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_NEAR(total_area(r.footprint), 100, 1e-9);
}

TEST(ExplicitFootprint, SliversFlippedByQuantizationAreNotTheWholeBottom) {
  // Walls and roof turned outward, the bottom turned inward (facing up, as the lowest faces are in a
  // bag of triangles exported so), and three slivers of the bottom's triangulation, a few cm² each,
  // flipped over by quantized positions: they alone face down. The bottom is the whole 12 x 10 m.
  Mesh m;
  m.source_id = "flipped";
  add_box(m, 0, 0, 0, 12, 10, 10);
  std::reverse(m.indices.begin() + m.ring_offsets[0] + 1, m.indices.begin() + m.ring_offsets[1]);  // bottom up
  for (double x : {2.0, 5.0, 8.0})  // down-facing (clockwise in plan), 1 m long and 4 cm wide: 0.02 m²
    m.add_face({{{x, 3, 0.01}, {x + 0.5, 3.04, 0.01}, {x + 1, 3, 0.01}}}, SurfaceKind::Unknown, 1);
  FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.method, FootprintMethod::SolidBottom);
  EXPECT_GE(total_area(r.footprint), 120 - 1e-9);
  EXPECT_TRUE(r.misses_ground.empty()) << r.misses_ground;
}

TEST(ExplicitFootprint, ASolidBottomLeavingOutLowestFacesIsSaid) {
  // A closed box turned outward (its bottom faces down) and, beside it, an up-facing face at ground level
  // (a terrace's top drawn with the building): the bottom is the box's (down-facing, as much plan as the
  // up-facing face), and the ground left out under that lowest face is said with its area.
  Mesh m;
  add_box(m, 0, 0, 0, 10, 10, 10);
  m.add_face({{{10, 0, 0.2}, {14, 0, 0.2}, {14, 10, 0.2}, {10, 10, 0.2}}}, SurfaceKind::Unknown, 1);  // up, 40 m²
  FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.method, FootprintMethod::SolidBottom);
  EXPECT_NEAR(total_area(r.footprint), 100, 1e-9);
  EXPECT_NE(r.misses_ground.find("leaves out 40.0 m2"), std::string::npos) << r.misses_ground;
  // Without it, nothing is said.
  Mesh box;
  add_box(box, 0, 0, 0, 10, 10, 10);
  EXPECT_TRUE(make_footprint(box).misses_ground.empty());
}

TEST(ExplicitFootprint, SeveralGroundSurfacesWithHolesWinOverEverythingElse) {
  Mesh m;
  add_box(m, 0, 0, 0, 10, 10, 10);
  m.add_face({{{20, 0, 0}, {30, 0, 0}, {30, 10, 0}, {20, 10, 0}}, {{22, 2, 0}, {22, 4, 0}, {24, 4, 0}, {24, 2, 0}}},
             SurfaceKind::Ground, 2);
  m.add_face({{{40, 0, 0}, {45, 0, 0}, {45, 5, 0}}}, SurfaceKind::Ground, 2);
  // a vertical face mislabelled as ground has no area in plan: ignored
  m.add_face({{{0, 0, 0}, {5, 0, 0}, {5, 0, 5}, {0, 0, 5}}}, SurfaceKind::Ground, 2);
  m.add_face({{{0, 0, 0}, {5, 0, 0}, {5, 5, 0}}}, SurfaceKind::FootPrint, 0);
  FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.method, FootprintMethod::GroundSurface);
  ASSERT_EQ(r.footprint.polygons.size(), 2u);
  ASSERT_EQ(r.footprint.polygons[0].holes.size(), 1u);
  EXPECT_NEAR(total_area(r.footprint), 100 - 4 + 12.5, 1e-9);
}

TEST(ExplicitFootprint, Lod0FootPrintBeforeSolidBottom) {
  Mesh m;
  m.add_face({{{0, 0, 5}, {8, 0, 5}, {8, 6, 5}, {0, 6, 5}}}, SurfaceKind::RoofEdge, 0);
  m.add_face({{{0, 0, 0}, {8, 0, 0}, {8, 6, 0}, {0, 6, 0}}}, SurfaceKind::FootPrint, 0);
  FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.method, FootprintMethod::FootPrint);
  EXPECT_NEAR(total_area(r.footprint), 48, 1e-9);
}

TEST(ExplicitFootprint, SteppedBottomWithinTheLevelTolerance) {
  Mesh m;
  add_box(m, 0, 0, 0, 10, 10, 10);
  add_box(m, 10, 0, 0.3, 20, 10, 10);  // a neighbouring block 30 cm higher: same building, same level
  FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.footprint.polygons.size(), 2u);
  FootprintParams strict;
  strict.level_tolerance_m = 0.1;
  EXPECT_EQ(make_footprint(m, strict).footprint.polygons.size(), 1u);
}

TEST(ExplicitFootprint, NoGroundGeometryGivesAReason) {
  Mesh walls;  // four walls, nothing horizontal
  add_box(walls, 0, 0, 0, 10, 10, 10);
  Mesh only_walls;
  for (std::uint32_t f = 2; f < 6; ++f) {
    Rings r(1);
    for (std::uint32_t k = walls.ring_offsets[walls.faces[f].first_ring];
         k < walls.ring_offsets[walls.faces[f].first_ring + 1]; ++k)
      r[0].push_back(walls.vertices[walls.indices[k]]);
    only_walls.add_face(r, SurfaceKind::Wall, 2);
  }
  FootprintParams explicit_only;  // Auto would fall back to decomposition (issue 5) and succeed
  explicit_only.source = FootprintSource::GroundSurface;
  FootprintResult r = make_footprint(only_walls, explicit_only);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.code, "NO_GROUND_GEOMETRY");
  EXPECT_NE(r.reason.find("none of its 4 faces is horizontal"), std::string::npos) << r.reason;
  r = make_footprint(only_walls);
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.method, FootprintMethod::Decomposition);

  Mesh lid = only_walls;  // walls and a flat top, open at the bottom: the top is no footprint
  lid.add_face({{{0, 0, 10}, {10, 0, 10}, {10, 10, 10}, {0, 10, 10}}}, SurfaceKind::Unknown, 2);
  r = make_footprint(lid, explicit_only);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.code, "NO_GROUND_GEOMETRY");
  EXPECT_NE(r.reason.find("lowest level"), std::string::npos) << r.reason;

  Mesh edge;
  edge.add_face({{{0, 0, 5}, {8, 0, 5}, {8, 6, 5}}}, SurfaceKind::RoofEdge, 0);
  r = make_footprint(edge);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("RoofEdge"), std::string::npos) << r.reason;

  r = make_footprint(Mesh{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.code, "EMPTY_MESH");
}

TEST(ExplicitFootprint, DecomposeIgnoresTheExplicitGeometry) {
  // Issue 5 wired in: decomposition only (tests/unit/core/decompose_test.cpp has the hard cases).
  Mesh m;
  add_box(m, 0, 0, 0, 10, 10, 10);
  FootprintParams p;
  p.source = FootprintSource::Decompose;
  FootprintResult r = make_footprint(m, p);
  EXPECT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.method, FootprintMethod::Decomposition);
  ASSERT_EQ(r.footprint.polygons.size(), 1u);
  EXPECT_EQ(r.footprint.polygons[0].outer.size(), 4u);
  Mesh wall;  // one wall: no closed lower boundary, and the reason says so
  wall.add_face({{{0, 0, 0}, {10, 0, 0}, {10, 0, 3}, {0, 0, 3}}}, SurfaceKind::Wall, 2);
  r = make_footprint(wall, p);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.code, "NO_FOOTPRINT_LOOP");
  EXPECT_NE(r.reason.find("no closed lower wall boundary"), std::string::npos) << r.reason;
  p.source = FootprintSource::GroundSurface;
  EXPECT_TRUE(make_footprint(m, p).ok);
}

TEST(ExplicitFootprint, LargeUtmCoordinatesKeepPrecision) {
  Mesh m;
  add_box(m, 457842, 5439083, 100, 457854, 5439093, 106.5);
  FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.method, FootprintMethod::SolidBottom);
  EXPECT_NEAR(total_area(r.footprint), 120, 1e-6);
}

}  // namespace
}  // namespace groundplan

namespace groundplan {
namespace {

// Issue 20: a self-crossing ground ring is a footprint. A symmetric bow-tie has signed area 0; it was
// dropped as NO_GROUND_GEOMETRY. Its region by the even-odd rule (GEOS MakeValid) is two triangles.
TEST(ExplicitFootprint, SelfCrossingGroundRingIsAFootprint) {
  for (SurfaceKind kind : {SurfaceKind::Ground, SurfaceKind::FootPrint}) {
    Mesh m;
    m.source_id = "bowtie";
    m.add_face({{{0, 0, 0}, {10, 10, 0}, {10, 0, 0}, {0, 10, 0}}}, kind, kind == SurfaceKind::Ground ? 2 : 0);
    FootprintParams explicit_only;
    explicit_only.source = FootprintSource::GroundSurface;
    const FootprintResult r = make_footprint(m, explicit_only);
    ASSERT_TRUE(r.ok) << r.code << ": " << r.reason;
    ASSERT_EQ(r.footprint.polygons.size(), 1u);
    EXPECT_EQ(r.footprint.polygons[0].outer.size(), 4u);
  }
  // a figure-eight hole in a square stays a hole too
  Mesh m;
  m.add_face({{{0, 0, 0}, {20, 0, 0}, {20, 20, 0}, {0, 20, 0}}, {{5, 5, 0}, {15, 15, 0}, {15, 5, 0}, {5, 15, 0}}},
             SurfaceKind::Ground, 2);
  const FootprintResult r = make_footprint(m);
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.footprint.polygons.size(), 1u);
  EXPECT_EQ(r.footprint.polygons[0].holes.size(), 1u);
  // a ground face seen edge-on (a wall tagged GroundSurface) still has no area
  Mesh wall;
  wall.add_face({{{0, 0, 0}, {10, 0, 0}, {10, 0, 5}, {0, 0, 5}}}, SurfaceKind::Ground, 2);
  FootprintParams explicit_only;
  explicit_only.source = FootprintSource::GroundSurface;
  EXPECT_FALSE(make_footprint(wall, explicit_only).ok);
}

}  // namespace
}  // namespace groundplan

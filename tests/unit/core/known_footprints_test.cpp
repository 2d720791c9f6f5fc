// SPDX-License-Identifier: MIT
// Issue 21: every generated model with a known footprint (tests/support/known_footprints.h) through
// the decomposition (`--footprints decompose`): area within 1% of the true footprint, the same place
// (symmetric difference within 1%), and a valid footprint: every polygon GEOS-valid and no two
// overlapping (a MultiPolygon whose parts overlap is invalid in OGC and double-counts area).
#include "footprint/decompose.h"
#include "known_footprints.h"

#include <groundplan/footprint.h>
#include <groundplan/gis/geos_reference.h>
#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <sstream>

namespace groundplan::test {
/// gtest prints a case by its name, not its bytes.
void PrintTo(const KnownFootprint& k, std::ostream* os) { *os << k.name; }
}  // namespace groundplan::test

namespace groundplan::footprint {
namespace {

using test::KnownFootprint;

double ring_area(const Ring& r) {
  double a = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Point2 &p = r[i], &q = r[(i + 1) % r.size()];
    a += p.x * q.y - q.x * p.y;
  }
  return a / 2;
}

/// Sum of the polygons' areas (outer less holes): overlapping polygons count twice, as a reader of
/// the footprint layer would count them.
double summed_area(const std::vector<Polygon>& polys) {
  double a = 0;
  for (const Polygon& p : polys) {
    a += std::fabs(ring_area(p.outer));
    for (const Ring& h : p.holes) a -= std::fabs(ring_area(h));
  }
  return a;
}

class KnownFootprints : public ::testing::TestWithParam<KnownFootprint> {};

TEST_P(KnownFootprints, AreaWithinOnePercentAndValid) {
  const KnownFootprint& k = GetParam();
  const DecomposeResult r = decompose_footprint(k.mesh);
  ASSERT_FALSE(r.polygons.empty()) << k.name << ": no footprint";
  // Every generated model has its wall loops: the shadow (the true area for some families, e.g.
  // stepped_ground) would pass the area check by luck.
  EXPECT_FALSE(r.stats.shadow) << k.name << ": the shadow, not the walls' loops";
  const double area = summed_area(r.polygons);
  EXPECT_NEAR(area, k.true_area_m2, 0.01 * k.true_area_m2)
      << k.name << ": " << r.polygons.size() << " polygon(s), shadow " << r.stats.shadow << ", loops " << r.stats.loops
      << ", open chains " << r.stats.open_chains << " (true " << k.true_area_m2 << ", shadow " << k.shadow_area_m2 << ")";
  // Stacked parts and arcades as one closed mesh (plinth, podium, terraces, towers on one base, arcade): the
  // base to 0.1 %; the arcade's is its ground floor and pillars, not its shadow.
  for (const char* family : {"plinth", "podium", "podium_corner", "terraces", "multi_tower", "arcade"})
    if (k.family == family)
      EXPECT_NEAR(area, k.true_area_m2, 0.001 * k.true_area_m2) << k.name << " (shadow " << k.shadow_area_m2 << ")";
  // Against the true footprint, and each polygon valid (GEOS).
  Footprint truth;
  truth.polygons = gis::polygons_from_wkt(k.true_wkt);
  std::vector<GroundPlan> ours;
  for (const Polygon& p : r.polygons) ours.push_back(GroundPlan{p, {}, 0});
  const gis::GeosComparison g = gis::compare_with_geos({truth}, ours);
  EXPECT_EQ(g.invalid_ours, 0u) << k.name << ": " << g.summary();
  EXPECT_LE(g.symdiff_area, 0.01 * k.true_area_m2) << k.name << ": " << g.summary();
  // No two polygons overlap: their union has the area of their sum.
  Footprint mine;
  mine.polygons = r.polygons;
  double united = 0;
  for (const GroundPlan& u : gis::geos_union({mine})) united += summed_area({u.polygon});
  EXPECT_NEAR(united, area, 1e-6 * std::max(1.0, area)) << k.name << ": the footprint's polygons overlap";
}

/// The generator itself: the union of every face's vertical projection is the shadow it states, and
/// the true footprint lies inside it (a wrong model would make the test above meaningless).
TEST(KnownFootprintGenerator, ShadowAndTruthAgreeWithTheModel) {
  const std::vector<KnownFootprint> all = test::known_footprints();
  ASSERT_EQ(all.size(), test::known_footprint_families().size() * 6);
  for (const KnownFootprint& k : all) {
    if (k.writing == test::Writing::Soup) continue;  // jittered: projections of vertical faces are slivers
    Footprint proj;
    for (std::size_t f = 0; f < k.mesh.faces.size(); ++f) {
      const MeshFace& mf = k.mesh.faces[f];
      Ring ring;
      for (std::uint32_t i = k.mesh.ring_offsets[mf.first_ring]; i < k.mesh.ring_offsets[mf.first_ring + 1]; ++i)
        ring.push_back({k.mesh.vertices[k.mesh.indices[i]].x, k.mesh.vertices[k.mesh.indices[i]].y});
      const double a = ring_area(ring);
      if (std::fabs(a) < 1e-9) continue;  // vertical
      if (a < 0) std::reverse(ring.begin(), ring.end());
      proj.polygons.push_back(Polygon{ring, {}});
    }
    double shadow = 0;
    for (const GroundPlan& u : gis::geos_union({proj})) shadow += summed_area({u.polygon});
    EXPECT_NEAR(shadow, k.shadow_area_m2, 1e-6) << k.name;
    Footprint truth;
    truth.polygons = gis::polygons_from_wkt(k.true_wkt);
    EXPECT_NEAR(summed_area(truth.polygons), k.true_area_m2, 1e-9) << k.name;
    proj.polygons.insert(proj.polygons.end(), truth.polygons.begin(), truth.polygons.end());
    double both = 0;
    for (const GroundPlan& u : gis::geos_union({proj})) both += summed_area({u.polygon});
    EXPECT_NEAR(both, k.shadow_area_m2, 1e-6) << k.name << ": the true footprint reaches outside the model";
  }
}

/// Four walls whose ends stop `gap` short of each corner, under a flat roof (no floor).
Mesh gappy_walls(double g) {
  Mesh m;
  auto wall = [&](Point3 a, Point3 b) { m.add_face({{a, b, {b.x, b.y, 3}, {a.x, a.y, 3}}}, SurfaceKind::Unknown, 255); };
  wall({g, 0, 0}, {10 - g, 0, 0});
  wall({10, g, 0}, {10, 8 - g, 0});
  wall({10 - g, 8, 0}, {g, 8, 0});
  wall({0, 8 - g, 0}, {0, g, 0});
  m.add_face({{{0, 0, 3}, {10, 0, 3}, {10, 8, 3}, {0, 8, 3}}}, SurfaceKind::Unknown, 255);
  return m;
}

/// The shadow only as the last resort, and then said why (issue 21): four walls with 0.5 m gaps at the
/// corners close no loop, in 3D or in plan, so the footprint is the shadow and the note says the loops
/// failed; a true model gets its loop and no note. (Until stage 7c the gaps were 5 cm: those close in
/// plan now, the next test.)
TEST(FootprintShadowNote, SaysWhyTheLoopsFailed) {
  const Mesh gappy = gappy_walls(0.5);
  FootprintParams params;
  params.source = FootprintSource::Decompose;
  const FootprintResult shadow = make_footprint(gappy, params);
  ASSERT_TRUE(shadow.ok);
  EXPECT_EQ(shadow.method, FootprintMethod::DecompositionShadow);
  EXPECT_NE(shadow.note.find("footprint is the shadow: the walls' lower boundary closed no loop"), std::string::npos)
      << shadow.note;
  params.source = FootprintSource::Auto;  // no ground faces either: the explicit route's failure comes first
  const FootprintResult autom = make_footprint(gappy, params);
  EXPECT_EQ(autom.method, FootprintMethod::DecompositionShadow);
  EXPECT_EQ(autom.note.rfind("no GroundSurface", 0), 0u) << autom.note;
  EXPECT_NE(autom.note.find("; footprint is the shadow"), std::string::npos) << autom.note;
  for (const KnownFootprint& k : test::known_footprints())
    if (k.name == "slab_roof_polygons_open") {
      params.source = FootprintSource::Decompose;
      const FootprintResult loop = make_footprint(k.mesh, params);
      EXPECT_EQ(loop.method, FootprintMethod::Decomposition);
      EXPECT_TRUE(loop.note.empty()) << loop.note;
    }
}

/// Stage 7c (plan_faces.cpp): walls ending 5 cm short of each corner (the ends 7 cm apart, as Macky's
/// SketchUp parts) close in plan: the footprint is the walls' rectangle, not the roof's shadow (which
/// here is the same rectangle, so the method and the note tell them apart), with a note that says so.
/// A dangling wall outside (a garden wall, 3 m of 39 m) still lets it close; a longer one (12 m) does not.
TEST(FootprintClosedInPlan, GapsBetweenPartsCloseInPlan) {
  FootprintParams params;
  params.source = FootprintSource::Decompose;
  Mesh m = gappy_walls(0.05);
  const FootprintResult r = make_footprint(m, params);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.method, FootprintMethod::Decomposition);
  EXPECT_NE(r.note.find("footprint closed in plan, not the shadow"), std::string::npos) << r.note;
  const DecomposeResult d = decompose_footprint(m);
  EXPECT_TRUE(d.stats.closed_in_plan);
  EXPECT_FALSE(d.stats.shadow);
  ASSERT_EQ(d.polygons.size(), 1u);
  EXPECT_NEAR(summed_area(d.polygons), 80, 80 * 0.01);
  EXPECT_EQ(d.polygons[0].outer.size(), 4u);  // the ends joined: the corners, no slivers
  for (double len : {3.0, 12.0}) {
    Mesh g = gappy_walls(0.05);
    g.add_face({{{10, 8, 0}, {10 + len, 8, 0}, {10 + len, 8, 1}, {10, 8, 1}}}, SurfaceKind::Unknown, 255);
    const DecomposeResult e = decompose_footprint(g);
    EXPECT_EQ(e.stats.closed_in_plan, len < 5) << len;
    EXPECT_EQ(e.stats.shadow, len > 5) << len;
  }
}

std::string case_name(const ::testing::TestParamInfo<KnownFootprint>& info) { return info.param.name; }

// Every case: balcony (contacts.cpp, rule c) and stepped ground with its floor (classification.cpp, a
// floor much deeper than its riser is a step of the ground) were the last to pass.
INSTANTIATE_TEST_SUITE_P(Generated, KnownFootprints, ::testing::ValuesIn(test::known_footprints()), case_name);

}  // namespace
}  // namespace groundplan::footprint

// SPDX-License-Identifier: MIT
// A footprint that does not trust the footprint (core/src/footprint/ground_check.h): the building's lowest
// horizontal faces must lie inside its footprint. A footprint that leaves ground out (injected: the tower's
// outline for a building on a plinth) is FOOTPRINT_MISSES_GROUND with the areas; the right footprint, and
// an arcade's ground floor and pillars (smaller than its shadow), are not.
#include "footprint/decompose.h"
#include "footprint/ground_check.h"
#include "known_footprints.h"

#include <groundplan/footprint.h>
#include <groundplan/gis/geos_reference.h>
#include <gtest/gtest.h>

namespace groundplan::footprint {
namespace {

const test::KnownFootprint& known(const std::string& name) {
  static const std::vector<test::KnownFootprint> all = test::known_footprints();
  for (const test::KnownFootprint& k : all)
    if (k.name == name) return k;
  throw std::runtime_error("no generated building " + name);
}

Polygon rect(double x0, double y0, double x1, double y1) { return Polygon{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}}; }

TEST(GroundCheck, ATowerOutlineForABuildingOnAPlinthMissesGround) {
  for (const char* name : {"plinth_polygons_floor", "plinth_triangles_floor", "plinth_soup_floor"}) {
    const test::KnownFootprint& k = known(name);
    const GroundCheck wrong = check_ground(k.mesh, {rect(7.5, 7.5, 22.5, 22.5)}, FootprintParams{});
    EXPECT_TRUE(wrong.misses_ground()) << name;
    EXPECT_NEAR(wrong.footprint_m2, 225, 1e-9) << name;
    EXPECT_NEAR(wrong.lowest_m2, 900, 0.5) << name;
    EXPECT_NEAR(wrong.uncovered_m2, 675, 0.5) << name;
    EXPECT_NE(wrong.reason().find("the footprint (225.0 m2) leaves out 675.0 m2 of ground under the building's lowest "
                                  "horizontal faces"),
              std::string::npos)
        << wrong.reason();
    const GroundCheck right = check_ground(k.mesh, gis::polygons_from_wkt(k.true_wkt), FootprintParams{});
    EXPECT_FALSE(right.misses_ground()) << name << ": " << right.reason();
  }
}

TEST(GroundCheck, AnArcadeIsItsGroundFloorAndPillarsNotItsShadow) {
  const test::KnownFootprint& k = known("arcade_polygons_floor");
  EXPECT_FALSE(check_ground(k.mesh, gis::polygons_from_wkt(k.true_wkt), FootprintParams{}).misses_ground());
  // Without the pillars the footprint leaves out 0.5 m² of ground: over 0.1 % of the ground floor.
  const GroundCheck no_pillars = check_ground(k.mesh, {rect(0, 3, 10, 10)}, FootprintParams{});
  EXPECT_TRUE(no_pillars.misses_ground());
  EXPECT_NEAR(no_pillars.uncovered_m2, 0.5, 1e-9);
}

// No false alarm: every generated building with its floor, through make_footprint (decomposition).
TEST(GroundCheck, TheDecompositionsOwnFootprintsPass) {
  FootprintParams params;
  params.source = FootprintSource::Decompose;
  for (const test::KnownFootprint& k : test::known_footprints()) {
    const FootprintResult r = make_footprint(k.mesh, params);
    ASSERT_TRUE(r.ok) << k.name;
    EXPECT_TRUE(r.misses_ground.empty()) << k.name << ": " << r.misses_ground;
  }
}

}  // namespace
}  // namespace groundplan::footprint

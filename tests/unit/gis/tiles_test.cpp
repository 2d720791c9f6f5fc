// SPDX-License-Identifier: MIT
// The tiled run's pieces (issue 15): the extents index that decides final vs seam, and the spill round trip.
#include "pipeline/plan_spill.h"
#include "pipeline/tile_extents.h"

#include <groundplan/error.h>
#include <groundplan/gis/tiled.h>

#include "test_support.h"

#include <gtest/gtest.h>

namespace groundplan::gis::detail {
namespace {

TEST(TileExtents, TouchingCountsOwnTileDoesNot) {
  // Three 100 m tiles in a row and one far away; an empty tile meets nothing.
  const TileExtents index({{0, 0, 100, 100}, {100, 0, 200, 100}, {200, 0, 300, 100}, {5000, 5000, 5100, 5100},
                           empty_box()});
  EXPECT_FALSE(index.meets_other({10, 10, 20, 20}, 0));     // inside tile 0 only
  EXPECT_TRUE(index.meets_other({90, 10, 100, 20}, 0));     // touches tile 1's extent at x = 100
  EXPECT_FALSE(index.meets_other({90, 10, 99.999, 20}, 0)); // just short of it
  EXPECT_TRUE(index.meets_other({150, 40, 250, 60}, 1));    // across into tile 2
  EXPECT_FALSE(index.meets_other({5010, 5010, 5020, 5020}, 3));
  EXPECT_TRUE(index.meets_other({5010, 5010, 5020, 5020}, 4));  // seen from another tile, tile 3 is met
  EXPECT_FALSE(index.meets_other(empty_box(), 0));
}

TEST(TileExtents, LargeTileIsFoundToo) {
  // Many small tiles make the grid fine; one huge tile covers thousands of its cells.
  std::vector<Box> extents;
  for (int i = 0; i < 50; ++i) extents.push_back({i * 10.0, 0, i * 10.0 + 10, 10});
  extents.push_back({0, 1000, 500, 2000});
  const TileExtents index(std::move(extents));
  EXPECT_TRUE(index.meets_other({250, 1500, 251, 1501}, 0));
  EXPECT_FALSE(index.meets_other({250, 1500, 251, 1501}, 50));
}

TEST(PlanSpill, RoundTripWithAndWithoutPolygons) {
  PlanSpill spill;
  Footprint a;
  a.source_id = "A";
  a.source_file = "t1.gml";
  a.method = "ground-surface";
  a.min_z = 1;
  a.max_z = 9;
  a.polygons = {Polygon{{{0, 0}, {4, 0}, {4, 4}, {0, 4}}, {{{1, 1}, {1, 2}, {2, 2}}}}};
  Footprint b = a;
  b.source_id = "B";
  b.polygons = {Polygon{{{4, 0}, {8, 0}, {8, 4}}, {}}, Polygon{{{10, 10}, {11, 10}, {11, 11}}, {}}};
  GroundPlan gp;
  gp.polygon = Polygon{{{0, 0}, {8, 0}, {8, 4}, {0, 4}}, {{{1, 1}, {1, 2}, {2, 2}}}};
  gp.members = {7, 12};
  gp.area_m2 = 31.5;
  const std::uint64_t first = spill.append(gp, {&a, &b}, 3, {0, 0, 8, 4});
  gp.members = {13};
  const std::uint64_t second = spill.append(gp, {&b}, 4, {1, 2, 3, 4});
  spill.flush();
  std::uint64_t next = 0;
  const SpilledPlan s = spill.read(first, true, &next);
  EXPECT_EQ(next, second);
  EXPECT_EQ(s.tile, 3u);
  EXPECT_EQ(s.box, (Box{0, 0, 8, 4}));
  EXPECT_EQ(s.plan.members, (std::vector<std::uint32_t>{7, 12}));
  EXPECT_EQ(s.plan.area_m2, 31.5);
  EXPECT_EQ(s.plan.polygon.outer, gp.polygon.outer);
  ASSERT_EQ(s.plan.polygon.holes.size(), 1u);
  ASSERT_EQ(s.footprints.size(), 2u);
  EXPECT_EQ(s.footprints[0].source_id, "A");
  EXPECT_EQ(s.footprints[0].source_file, "t1.gml");
  EXPECT_EQ(s.footprints[0].method, "ground-surface");
  EXPECT_EQ(s.footprints[0].max_z, 9);
  ASSERT_EQ(s.footprints[0].polygons.size(), 1u);
  EXPECT_EQ(s.footprints[0].polygons[0].holes[0], a.polygons[0].holes[0]);
  ASSERT_EQ(s.footprints[1].polygons.size(), 2u);
  EXPECT_EQ(s.footprints[1].polygons[1].outer, b.polygons[1].outer);
  const SpilledPlan t = spill.read(second, false, &next);
  EXPECT_EQ(next, spill.size());
  EXPECT_EQ(t.tile, 4u);
  EXPECT_EQ(t.plan.members, (std::vector<std::uint32_t>{13}));
  EXPECT_EQ(t.footprints[0].source_id, "B");
  EXPECT_TRUE(t.footprints[0].polygons.empty());
  EXPECT_THROW(spill.read(spill.size(), true), Error);
}

// --tiles auto weighs files by what their footprints take in one process: a 2D OGR layer several times its
// bytes, a city model a fraction of them.
TEST(TilesAuto, FootprintMemoryIsEstimatedByKindOfFile) {
  const test::TempDir dir("groundplan_tiles_auto");
  dir.file("tiles/a.gml", std::string(1000, ' '));
  dir.file("tiles/b.geojson", std::string(2000, ' '));
  dir.file("tiles/notes.txt", std::string(5000, ' '));  // not an input: not counted
  std::size_t files = 0;
  EXPECT_EQ(estimated_footprint_bytes({(dir.path / "tiles").string()}, &files), 150u + 10000u);
  EXPECT_EQ(files, 2u);
  EXPECT_EQ(estimated_footprint_bytes({(dir.path / "tiles" / "a.gml").string()}, &files), 150u);
  EXPECT_EQ(files, 1u);
}

}  // namespace
}  // namespace groundplan::gis::detail

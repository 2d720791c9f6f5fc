// SPDX-License-Identifier: MIT
// Feature ranges of one OGR source (issue 22): how layers are cut, that the ranges read one after the
// other give read_ogr's meshes and problems in its order, and that ranges which do not meet are seen.
#include <groundplan/gis/ogr_input.h>
#include <groundplan/gis/ogr_ranges.h>

#include <cpl_vsi.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace groundplan::gis {
namespace {

/// A GeoJSON (GDAL's OLCFastSetNextByIndex) of n squares in EPSG:25832; every fifth has no geometry.
std::string squares(const std::string& path, int n) {
  std::string text = R"({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::25832"}}, "features": [)";
  for (int i = 0; i < n; ++i) {
    const std::string x0 = std::to_string(400000 + 20 * i), x1 = std::to_string(400010 + 20 * i);
    text += std::string(i ? "," : "") + R"({"type": "Feature", "properties": {"name": "b)" + std::to_string(i) + R"("}, "geometry": )" +
            (i % 5 == 4 ? std::string("null")
                        : R"({"type": "Polygon", "coordinates": [[[)" + x0 + ",5800000],[" + x1 + ",5800000],[" + x1 +
                              ",5800010],[" + x0 + ",5800000]]]}") + "}";
  }
  text += "]}";
  VSILFILE* f = VSIFOpenL(path.c_str(), "wb");
  VSIFWriteL(text.data(), 1, text.size(), f);
  VSIFCloseL(f);
  return path;
}

std::vector<std::string> ids(const std::vector<Mesh>& meshes) {
  std::vector<std::string> out;
  for (const Mesh& m : meshes) out.push_back(m.source_id);
  return out;
}

std::vector<std::string> said(const std::vector<Problem>& problems) {
  std::vector<std::string> out;
  for (const Problem& p : problems) out.push_back(p.source_id + " " + p.code + " " + p.reason);
  return out;
}

TEST(OgrRanges, RangesReadOneAfterTheOtherAreTheWholeReading) {
  const std::string path = squares("/vsimem/ogr_ranges_whole.geojson", 23);
  OgrInputOptions o;
  o.id_field = "name";
  std::vector<Mesh> whole;
  std::vector<Problem> whole_problems;
  OgrInfo info;
  read_ogr(path, o, {}, [&](Mesh&& m) { whole.push_back(std::move(m)); }, whole_problems, info);

  const OgrRangePlan plan = plan_ogr_ranges(path, o, 4, 2);
  ASSERT_EQ(plan.why_not, "");
  ASSERT_EQ(plan.ranges.size(), 6u);  // 23 features in 6 ranges of 3-4
  EXPECT_EQ(plan.ranges.front().begin, 0);
  EXPECT_EQ(plan.ranges.back().end, 23);
  EXPECT_EQ(plan.source_srs, "EPSG:25832");
  std::vector<Mesh> ranged;
  std::vector<Problem> problems = plan.head;
  std::vector<OgrRangeWatch> watches(plan.ranges.size());
  for (std::size_t k = 0; k < plan.ranges.size(); ++k)
    read_ogr_range(path, o, plan, k, [&](Mesh&& m) { ranged.push_back(std::move(m)); }, problems, watches[k]);
  EXPECT_EQ(check_ogr_ranges(plan, watches), "");
  EXPECT_EQ(ids(ranged), ids(whole));
  EXPECT_EQ(said(problems), said(whole_problems));
  EXPECT_EQ(whole.size() + whole_problems.size(), 23u);  // features = members + problems
  VSIUnlink(path.c_str());
}

TEST(OgrRanges, RangesThatDoNotMeetOrMissFeaturesAreSeen) {
  OgrRangePlan plan;
  plan.ranges = {{0, false, 0, 3}, {0, false, 3, 6}};
  plan.layer_features = {6};
  std::vector<OgrRangeWatch> w(2);
  w[0] = {3, 0, 3};
  w[1] = {3, 3, -1};
  EXPECT_EQ(check_ogr_ranges(plan, w), "");
  w[0].next_fid = 4;  // a record skipped at the edge: range 1 would not end where range 2 begins
  EXPECT_NE(check_ogr_ranges(plan, w).find("does not end where the next range begins"), std::string::npos);
  w[0].next_fid = 3;
  w[1].next_fid = 6;  // features after the counted end
  EXPECT_NE(check_ogr_ranges(plan, w).find("after its counted end"), std::string::npos);
  w[1] = {2, 3, -1};  // a range cut short
  EXPECT_NE(check_ogr_ranges(plan, w).find("2 features read, 3 expected"), std::string::npos);
  plan.ranges = {{0, true, 1, 50}, {0, true, 50, 100}};  // FID ranges: only the total can be checked
  w[0] = {3, 1, -1};
  w[1] = {2, 50, -1};
  plan.layer_features = {6};
  EXPECT_NE(check_ogr_ranges(plan, w).find("the ranges read 5 features, the layer counts 6"), std::string::npos);
}

TEST(OgrRanges, GroupBySqlAndWhereAreReadWhole) {
  const std::string path = squares("/vsimem/ogr_ranges_flags.geojson", 10);
  OgrInputOptions o;
  o.group_by = "name";
  EXPECT_EQ(plan_ogr_ranges(path, o, 2, 2).why_not.rfind("--group-by", 0), 0u);
  o = {};
  o.where = "name <> 'b1'";
  EXPECT_EQ(plan_ogr_ranges(path, o, 2, 2).why_not.rfind("--input-where", 0), 0u);
  o = {};
  o.sql = "SELECT * FROM ogr_ranges_flags";
  const OgrRangePlan plan = plan_ogr_ranges(path, o, 2, 2);
  EXPECT_EQ(plan.why_not.rfind("--input-sql", 0), 0u);
  EXPECT_TRUE(plan.ranges.empty());
  VSIUnlink(path.c_str());
}

}  // namespace
}  // namespace groundplan::gis

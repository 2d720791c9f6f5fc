// SPDX-License-Identifier: MIT
// The whole pipeline on real city models, checked against GEOS UnaryUnion through the C API
// (gis/geosref): same polygons and holes, symmetric difference <= 1e-9 of the area, all valid, and
// nothing lost (every building read is a footprint or a problem; every footprint is in a plan).
#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/gis/pipeline.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "test_support.h"

namespace groundplan {
namespace {

struct Case {
  const char* path;  // relative to sample_data/ or ../shared/data
  bool shared;
  std::size_t buildings;
  std::size_t plans;
  std::size_t holes;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.path; }

class PipelineOnRealData : public ::testing::TestWithParam<Case> {};

TEST_P(PipelineOnRealData, MatchesGeosAndLosesNothing) {
  const Case& c = GetParam();
  gis::PipelineOptions options;
  options.inputs = {c.shared ? test::shared_data(c.path) : test::sample_data(c.path)};
  const gis::PipelineResult r = gis::run_pipeline(options);

  EXPECT_EQ(r.buildings_read, c.buildings);
  EXPECT_EQ(r.plans.size(), c.plans);
  std::size_t holes = 0;
  for (const auto& p : r.plans) holes += p.polygon.holes.size();
  EXPECT_EQ(holes, c.holes);
  EXPECT_FALSE(r.crs_wkt.empty());

  const gis::GeosComparison cmp = gis::compare_with_geos(r.footprints, r.plans);
  EXPECT_TRUE(cmp.matches(1e-9)) << cmp.summary();

  // Nothing lost.
  std::size_t building_problems = 0;
  for (const auto& p : r.problems) building_problems += !p.source_id.empty() && p.code != "NOTE";
  EXPECT_EQ(r.buildings_read, r.footprints.size() + building_problems);
  std::set<std::uint32_t> members;
  for (const auto& p : r.plans) members.insert(p.members.begin(), p.members.end());
  std::set<std::string> union_problems;
  for (const auto& p : r.problems)
    if (p.stage == "union") union_problems.insert(p.source_id);
  for (std::uint32_t i = 0; i < r.footprints.size(); ++i)
    EXPECT_TRUE(members.count(i) || union_problems.count(r.footprints[i].source_id))
        << "footprint " << r.footprints[i].source_id << " is in no plan and has no problem";
}

// Expected counts: sample_data/README.md (and GEOS UnaryUnion of the same footprints).
INSTANTIATE_TEST_SUITE_P(
    Samples, PipelineOnRealData,
    ::testing::Values(Case{"plateau-niiza/53395404_bldg_6697_op.gml", false, 657, 650, 0},
                      Case{"plateau-niiza/53392547_bldg_6697_op2.gml", false, 25, 23, 0},
                      Case{"niedersachsen-lorup/LoD1_24065862_2_2021-01-25.gml", false, 104, 64, 6},
                      Case{"tum-main-entrance/TUM-Main-Entrance.gml", false, 1, 1, 1},
                      Case{"citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml", true, 61, 18, 39}));

TEST(Pipeline, MissingFileNamesTheFile) {
  gis::PipelineOptions options;
  options.inputs = {"/nonexistent/city.gml"};
  try {
    gis::run_pipeline(options);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/city.gml"), std::string::npos) << e.what();
  }
}

TEST(Pipeline, FolderOfTilesIsOneInput) {
  gis::PipelineOptions options;
  options.inputs = {test::shared_data("citygml1-niedersachsen-lod1-4tiles")};
  const gis::PipelineResult r = gis::run_pipeline(options);
  EXPECT_EQ(r.buildings_read, 408u + 259u - 0u) << "408 Buildings + 259 BuildingParts (SOURCE.txt)";
  const gis::GeosComparison cmp = gis::compare_with_geos(r.footprints, r.plans);
  EXPECT_TRUE(cmp.matches(1e-9)) << cmp.summary();
}

TEST(Pipeline, CancelStopsTheWork) {
  gis::PipelineOptions options;
  options.inputs = {test::sample_data("plateau-niiza/53395404_bldg_6697_op.gml")};
  int calls = 0;
  const Progress cancel_at_once([&](double, const char*) { return ++calls < 2; });
  EXPECT_THROW(gis::run_pipeline(options, cancel_at_once), Cancelled);
}

// A folder whose first file has no CRS: its coordinates are kept as written, so a later file with a
// CRS must not be projected into some UTM zone and mixed with them; it is refused with a problem.
TEST(Pipeline, FileWithoutCrsIsNotMixedWithGeoreferencedFiles) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "groundplan_mixed_crs_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(test::shared_data("citygml1-berlin-lod2-libcitygml/b1_lod2_s.gml"), dir / "a_no_crs.gml");
  fs::copy_file(test::sample_data("tum-main-entrance/TUM-Main-Entrance.gml"), dir / "b_utm32.gml");
  gis::PipelineOptions options;
  options.inputs = {dir.string()};
  const gis::PipelineResult r = gis::run_pipeline(options);
  fs::remove_all(dir);
  EXPECT_TRUE(r.crs_wkt.empty()) << r.crs_name;
  bool refused = false;
  for (const auto& p : r.problems)
    refused |= p.file.find("b_utm32.gml") != std::string::npos && p.stage == "georeference" &&
               p.reason.find("a_no_crs.gml") != std::string::npos;
  EXPECT_TRUE(refused) << "no problem names the mix";
  for (const auto& f : r.footprints) EXPECT_EQ(f.source_file.find("b_utm32.gml"), std::string::npos) << f.source_id;
  ASSERT_FALSE(r.footprints.empty());
}

}  // namespace
}  // namespace groundplan

namespace groundplan {
namespace {

TEST(Pipeline, AxisOrderOptionPlacesALonLatFileWhereItIs) {
  // The OGC Jefferson Building sample says EPSG:4979 (lat, lon) but writes lon, lat. As written it
  // lands at "latitude -77" (UTM of the far south); with --axis-order east-north, in Washington DC.
  gis::PipelineOptions options;
  options.inputs = {test::shared_data(
      "citygml-ogc-spec-samples/JeffersonBuilding_CityGML3.0_LOD1_with_xAL3_CommonTypes.gml")};
  const gis::PipelineResult as_written = gis::run_pipeline(options);
  options.source_axis = gis::axis_order_from_string("east-north");
  const gis::PipelineResult swapped = gis::run_pipeline(options);
  ASSERT_EQ(swapped.plans.size(), 1u);
  EXPECT_EQ(swapped.crs_name, "EPSG:32618");  // UTM 18N
  EXPECT_NE(as_written.crs_name, swapped.crs_name);
  const Point2 p = swapped.plans[0].polygon.outer[0];
  EXPECT_NEAR(p.x, 325700, 1000);
  EXPECT_NEAR(p.y, 4306600, 1000);
  EXPECT_GT(swapped.plans[0].area_m2, 100);  // a building, not a degenerate sliver
  EXPECT_THROW(gis::axis_order_from_string("sideways"), InvalidArgument);
}

}  // namespace
}  // namespace groundplan

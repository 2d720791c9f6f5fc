// SPDX-License-Identifier: MIT
// -s_srs / -a_srs (issue 16): a CityGML file whose srsName says EPSG:4326 over UTM metres is refused
// with a message naming the flag; with PipelineOptions::s_srs it reads, in that CRS, with a NOTE.
#include <groundplan/error.h>
#include <groundplan/gis/pipeline.h>

#include <gtest/gtest.h>

#include <string>

#include "test_config.h"

namespace groundplan::gis {
namespace {

const std::string kFile = std::string(GROUNDPLAN_TEST_DATA_DIR) + "/corpus/bad/crs_4326_on_metres.gml";

TEST(SourceSrs, OverrideReadsAFileWhoseSrsNameIsWrong) {
  PipelineOptions o;
  o.inputs = {kFile};
  try {
    run_pipeline(o);
    ADD_FAILURE() << "EPSG:4326 over metres was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("-s_srs"), std::string::npos) << e.what();
  }
  o.s_srs = "EPSG:25832";
  const PipelineResult r = run_pipeline(o);
  EXPECT_GT(r.footprints.size(), 0u);
  EXPECT_EQ(r.crs_name, "EPSG:25832");
  bool noted = false;
  for (const Problem& p : r.problems) noted |= p.code == "NOTE" && p.reason.find("EPSG:25832 from -s_srs") != std::string::npos;
  EXPECT_TRUE(noted);
  // The coordinates stay as written: EPSG:25832 is the working CRS, nothing is transformed.
  ASSERT_FALSE(r.plans.empty());
  EXPECT_NEAR(r.plans[0].polygon.outer[0].x, 400000.0, 200.0);
}

}  // namespace
}  // namespace groundplan::gis

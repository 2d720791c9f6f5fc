// SPDX-License-Identifier: MIT
// The file's CRS against its area of use (issue 16): generated CityGML whose srsName does not fit its
// coordinates gives a CRS_OUTSIDE_AREA_OF_USE warning naming file, building, likely cause and flag;
// a building that collapses once placed says DEGENERATE_AFTER_GEOREFERENCING, not "no GroundSurface".
#include <groundplan/error.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/pipeline.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "test_support.h"

namespace groundplan::gis {
namespace {

/// One LoD2 building "B1" (a box with a GroundSurface) at (x0, y0), dx by dy, in srsName `srs`;
/// `north_first`: every position written northing/latitude first.
std::string citygml(const std::string& srs, double x0, double y0, double dx, double dy, bool north_first = false) {
  auto pos = [&](double x, double y, double z) {
    char b[96];
    if (north_first) std::swap(x, y);
    std::snprintf(b, sizeof b, "%.9f %.9f %.1f ", x, y, z);
    return std::string(b);
  };
  auto ring = [&](double z) {
    return pos(x0, y0, z) + pos(x0, y0 + dy, z) + pos(x0 + dx, y0 + dy, z) + pos(x0 + dx, y0, z) + pos(x0, y0, z);
  };
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\" "
         "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" xmlns:gml=\"http://www.opengis.net/gml\">\n"
         "<core:cityObjectMember><bldg:Building gml:id=\"B1\">"
         "<bldg:boundedBy><bldg:GroundSurface><bldg:lod2MultiSurface><gml:MultiSurface srsName=\"" + srs +
         "\" srsDimension=\"3\"><gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>" + ring(0) +
         "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember></gml:MultiSurface>"
         "</bldg:lod2MultiSurface></bldg:GroundSurface></bldg:boundedBy>"
         "</bldg:Building></core:cityObjectMember>\n</core:CityModel>\n";
}

const Problem* find(const PipelineResult& r, const std::string& code) {
  for (const Problem& p : r.problems)
    if (p.code == code) return &p;
  return nullptr;
}

std::string all(const PipelineResult& r) {
  std::string s;
  for (const Problem& p : r.problems) s += p.code + " [" + p.source_id + "]: " + p.reason + "\n";
  return s;
}

PipelineResult run(const std::vector<std::string>& files, AxisOrder axis = AxisOrder::Auto) {
  PipelineOptions o;
  o.inputs = files;
  o.source_axis = axis;
  return run_pipeline(o);
}

TEST(CrsAreaOfUse, ProjectedLabelOverDegreesWarnsAndSaysDegenerateAfterGeoreferencing) {
  const test::TempDir dir("groundplan_crs_area_test");
  // Karlsruhe in degrees (a 10 m by 9 m house) under ETRS89 / UTM 32N, whose numbers are metres.
  const std::string f = dir.file("deg_as_utm.gml", citygml("EPSG:25832", 8.4, 49.0, 0.00014, 0.00008));
  const PipelineResult r = run({f});
  const Problem* w = find(r, "CRS_OUTSIDE_AREA_OF_USE");
  ASSERT_TRUE(w) << all(r);
  EXPECT_EQ(w->source_id, "B1");
  EXPECT_EQ(w->file, f);
  EXPECT_EQ(w->stage, "read");  // a warning: georeference/footprint-stage problems with an id are drops
  EXPECT_EQ(r.buildings_read, r.footprints.size() + r.buildings_dropped);
  EXPECT_NE(w->reason.find("WARNING"), std::string::npos) << w->reason;
  EXPECT_NE(w->reason.find("EPSG:25832"), std::string::npos) << w->reason;
  EXPECT_NE(w->reason.find("degrees under a projected"), std::string::npos) << w->reason;
  EXPECT_NE(w->reason.find("-s_srs"), std::string::npos) << w->reason;
  // The building was fine as read; it is 1e-4 "metres" across once placed.
  const Problem* d = find(r, "DEGENERATE_AFTER_GEOREFERENCING");
  ASSERT_TRUE(d) << all(r);
  EXPECT_EQ(d->source_id, "B1");
  EXPECT_NE(d->reason.find("degenerate after georeferencing"), std::string::npos) << d->reason;
  EXPECT_EQ(r.footprints.size(), 0u);
  EXPECT_EQ(r.buildings_dropped, 1u);

  // Named as what it is, the same file gives its house and no warning.
  PipelineOptions o;
  o.inputs = {f};
  o.s_srs = "EPSG:4326";
  o.source_axis = AxisOrder::EastNorth;
  const PipelineResult ok = run_pipeline(o);
  EXPECT_FALSE(find(ok, "CRS_OUTSIDE_AREA_OF_USE")) << all(ok);
  EXPECT_FALSE(find(ok, "DEGENERATE_AFTER_GEOREFERENCING")) << all(ok);
  ASSERT_EQ(ok.plans.size(), 1u);
  EXPECT_NEAR(ok.plans[0].area_m2, 10.2 * 8.9, 5.0);
}

TEST(CrsAreaOfUse, GeographicLabelOverGaussKruegerMetres) {
  const test::TempDir dir("groundplan_crs_area_test");
  // Alone, EPSG:4326 over metres stops the file (WorkingFrame::decide, a message naming -s_srs).
  const std::string bad = dir.file("b_gk_as_4326.gml", citygml("EPSG:4326", 3457000, 5428000, 10, 9));
  try {
    run({bad});
    ADD_FAILURE() << "EPSG:4326 over Gauss-Krueger metres was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("-s_srs"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  // After a Gauss-Krueger file has fixed the working CRS, it is transformed straight to it: the
  // warning names the file, the building and the cause.
  const std::string good = dir.file("a_gk.gml", citygml("EPSG:31467", 3457100, 5428100, 10, 9));
  const PipelineResult r = run({good, bad});
  const Problem* w = find(r, "CRS_OUTSIDE_AREA_OF_USE");
  ASSERT_TRUE(w) << all(r);
  EXPECT_EQ(w->file, bad);
  EXPECT_EQ(w->source_id, "B1");
  EXPECT_NE(w->reason.find("metres under a geographic label"), std::string::npos) << w->reason;
  EXPECT_NE(w->reason.find("-s_srs"), std::string::npos) << w->reason;
  EXPECT_EQ(r.footprints.size(), 1u);  // the good file's
  // The bad file's building is dropped once (TRANSFORM_FAILED), not twice: one drop-stage problem names it.
  std::size_t drops = 0;
  for (const Problem& p : r.problems) drops += p.file == bad && p.source_id == "B1" && p.stage != "read";
  EXPECT_EQ(drops, 1u) << all(r);
  EXPECT_EQ(r.buildings_read, r.footprints.size() + r.buildings_dropped);
}

TEST(CrsAreaOfUse, SwappedAxesNameAxisOrder) {
  const test::TempDir dir("groundplan_crs_area_test");
  const std::string f = dir.file("swapped.gml", citygml("EPSG:25832", 456000, 5428000, 10, 9, true));
  const PipelineResult r = run({f});
  const Problem* w = find(r, "CRS_OUTSIDE_AREA_OF_USE");
  ASSERT_TRUE(w) << all(r);
  EXPECT_NE(w->reason.find("axes look swapped"), std::string::npos) << w->reason;
  EXPECT_NE(w->reason.find("--axis-order north-east"), std::string::npos) << w->reason;
  const PipelineResult ok = run({f}, AxisOrder::NorthEast);
  EXPECT_FALSE(find(ok, "CRS_OUTSIDE_AREA_OF_USE")) << all(ok);
  EXPECT_EQ(ok.footprints.size(), 1u);
}

// GDAL's GML convention: srsName "EPSG:4326" (short form) is longitude first; the URN form keeps EPSG's
// latitude first. The same house written each way lands in the same place.
TEST(CrsAreaOfUse, GmlShortEpsgIsLongitudeFirst) {
  const test::TempDir dir("groundplan_crs_area_test");
  const PipelineResult s = run({dir.file("short.gml", citygml("EPSG:4326", 8.4, 49.0, 0.00014, 0.00008))});
  const PipelineResult u = run({dir.file("urn.gml", citygml("urn:ogc:def:crs:EPSG::4326", 8.4, 49.0, 0.00014, 0.00008, true))});
  ASSERT_EQ(s.plans.size(), 1u);
  EXPECT_EQ(s.crs_name, "EPSG:32632");
  EXPECT_EQ(u.crs_name, "EPSG:32632");
  EXPECT_EQ(test::plan_keys(s.plans), test::plan_keys(u.plans));
  bool noted = false;
  for (const Problem& p : s.problems) noted |= p.code == "NOTE" && p.reason.find("short form") != std::string::npos;
  EXPECT_TRUE(noted) << all(s);
}

/// A file whose coordinates fit its CRS: no area-of-use problem, footprints made.
void expect_says_nothing(const std::string& f) {
  const PipelineResult r = run({f});
  EXPECT_FALSE(find(r, "CRS_OUTSIDE_AREA_OF_USE")) << f << "\n" << all(r);
  EXPECT_FALSE(find(r, "DEGENERATE_AFTER_GEOREFERENCING")) << f << "\n" << all(r);
  EXPECT_FALSE(r.footprints.empty()) << f;
}

TEST(CrsAreaOfUse, FittingFilesAndRealSamplesSayNothing) {
  const test::TempDir dir("groundplan_crs_area_test");
  for (const std::string& f : {dir.file("utm.gml", citygml("EPSG:25832", 456000, 5428000, 10, 9)),
                               dir.file("ll.gml", citygml("EPSG:4326", 8.4, 49.0, 0.00014, 0.00008)),
                               dir.file("urn.gml", citygml("urn:ogc:def:crs:EPSG::4326", 8.4, 49.0, 0.00014, 0.00008, true)),
                               test::shared_data("cityjson-3dbag-cjseq/3dbag_b2.city.json")})
    expect_says_nothing(f);
  // The frame's own answer, for a point inside and one far outside.
  const WorkingFrame frame("EPSG:25832");
  EXPECT_EQ(frame.area_of_use_mismatch(456000, 5428000), "");
  EXPECT_NE(frame.area_of_use_mismatch(8.4, 49.0), "");
}

TEST(CrsAreaOfUseThirdParty, CompoundUrnSampleSaysNothing) {
  const std::string f = test::shared_data("citygml-ogc-spec-samples/v2_Building_LOD2-EPSG25832.gml");
  GROUNDPLAN_SKIP_IF_MISSING(f);
  expect_says_nothing(f);
}

}  // namespace
}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
// srsName parsing and the working frame (issue 6): axis order on the PLATEAU sample, UTM choice,
// contradicting labels, unknown CRS, -t_srs.
#include <groundplan/error.h>
#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>

#include <gtest/gtest.h>
#include <proj.h>

#include "test_support.h"

#include <cmath>

namespace groundplan::gis {
namespace {

using test::shared_data;

TEST(SrsName, EveryCommonForm) {
  struct Case {
    const char* text;
    int epsg, vertical;
  } cases[] = {
      {"EPSG:25833", 25833, 0},
      {"epsg:4326", 4326, 0},
      {"EPSG:25832+5783", 25832, 5783},
      {"urn:ogc:def:crs:EPSG::28992", 28992, 0},
      {"urn:ogc:def:crs:EPSG:6.12:25832", 25832, 0},
      {"urn:x-ogc:def:crs:EPSG:4326", 4326, 0},
      {"urn:ogc:def:crs,crs:EPSG::25832,crs:EPSG::5783", 25832, 5783},
      {"urn:ogc:def:crs,crs:EPSG:6.12:3068,crs:EPSG:6.12:5783", 3068, 5783},
      {"http://www.opengis.net/def/crs/EPSG/0/6697", 6697, 0},
      {"https://www.opengis.net/def/crs/EPSG/0/3946", 3946, 0},
      {"http://www.opengis.net/def/crs-compound?1=http://www.opengis.net/def/crs/EPSG/0/25832&2=http://"
       "www.opengis.net/def/crs/EPSG/0/7837",
       25832, 7837},
      {"http://www.opengis.net/gml/srs/epsg.xml#4326", 4326, 0},
      {"urn:adv:crs:ETRS89_UTM32*DE_DHHN92_NH", 25832, 5783},
      {"urn:adv:crs:ETRS89_UTM32*DE_DHHN2016_NH", 25832, 7837},
      {"urn:adv:crs:ETRS89_UTM33", 25833, 0},
      {"urn:adv:crs:DE_DHDN_3GK3*DE_DHHN92_NH", 31467, 5783},
  };
  for (const Case& c : cases) {
    SrsName s = parse_srs_name(c.text);
    EXPECT_EQ(s.epsg, c.epsg) << c.text;
    EXPECT_EQ(s.vertical_epsg, c.vertical) << c.text;
    EXPECT_FALSE(s.local) << c.text;
    EXPECT_EQ(s.definition, "EPSG:" + std::to_string(c.epsg)) << c.text;
  }
  EXPECT_TRUE(parse_srs_name("").local);
  EXPECT_TRUE(parse_srs_name("#local-CRS-1").local);
  EXPECT_EQ(parse_srs_name("+proj=utm +zone=32 +ellps=GRS80").definition, "+proj=utm +zone=32 +ellps=GRS80");
}

TEST(WorkingFrame, ProjectedMetricSourceIsTheWorkingCrs) {
  WorkingFrame f("urn:ogc:def:crs,crs:EPSG:6.12:25832,crs:EPSG:6.12:5783");
  EXPECT_TRUE(f.source_known());
  EXPECT_TRUE(f.identity());
  EXPECT_TRUE(f.decided());
  EXPECT_EQ(f.working_crs().epsg, 25832);
  EXPECT_NE(f.working_crs().wkt.find("UTM zone 32N"), std::string::npos);
  double x = 457842, y = 5439083;
  EXPECT_TRUE(f.transform_point(x, y));
  EXPECT_EQ(x, 457842);
}

// A folder's later tiles get the working CRS the first one fixed as their target: where that is their own CRS
// (here the horizontal part of a compound srsName), nothing is transformed, exactly as for the first tile; another
// projected CRS is transformed through PROJ.
TEST(WorkingFrame, TargetThatIsTheSourceCrsTransformsNothing) {
  for (const char* source : {"EPSG:25832", "urn:ogc:def:crs:EPSG::25832", "urn:ogc:def:crs,crs:EPSG::25832,crs:EPSG::7837"}) {
    CrsOptions o;
    o.target_srs = "EPSG:25832";
    WorkingFrame f(source, o);
    EXPECT_TRUE(f.identity()) << source;
    EXPECT_EQ(f.working_crs().epsg, 25832) << source;
    double x = 457842.123456789, y = 5439083.987654321;
    EXPECT_TRUE(f.transform_point(x, y));
    EXPECT_EQ(x, 457842.123456789) << source;
    EXPECT_EQ(y, 5439083.987654321) << source;
  }
  CrsOptions o;
  o.target_srs = "EPSG:25832";
  WorkingFrame other("EPSG:25833", o);
  EXPECT_FALSE(other.identity());
  double x = 457842, y = 5439083;
  EXPECT_TRUE(other.transform_point(x, y));
  EXPECT_GT(std::fabs(x - 457842), 1000.0);  // zone 33 to zone 32: hundreds of kilometres
}

TEST(WorkingFrameThirdParty, FzkHausFootprintLandsInUtm32) {
  const std::string fzk = shared_data("citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml");
  GROUNDPLAN_SKIP_IF_MISSING(fzk);
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  SourceInfo info;
  read_citygml(fzk, {},
               [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
  ASSERT_EQ(meshes.size(), 1u);
  WorkingFrame f(info.srs_name);
  EXPECT_EQ(f.working_crs().epsg, 25832);
  ASSERT_TRUE(f.transform(meshes[0]));
  FootprintResult fp = make_footprint(meshes[0]);
  ASSERT_TRUE(fp.ok) << fp.reason;
  double lo_x = 1e18, lo_y = 1e18, hi_x = -1e18, hi_y = -1e18;
  for (const Polygon& p : fp.footprint.polygons)
    for (const Point2& q : p.outer) {
      lo_x = std::min(lo_x, q.x), hi_x = std::max(hi_x, q.x);
      lo_y = std::min(lo_y, q.y), hi_y = std::max(hi_y, q.y);
    }
  EXPECT_NEAR(lo_x, 457842, 0.5);
  EXPECT_NEAR(lo_y, 5439083, 0.5);
  EXPECT_NEAR(hi_x - lo_x, 12, 0.5);
  EXPECT_NEAR(hi_y - lo_y, 10, 0.5);

  // The same house in WGS 84 / UTM 32N through -t_srs: within a metre of ETRS89 / UTM 32N.
  CrsOptions to_wgs;
  to_wgs.target_srs = "EPSG:32632";
  WorkingFrame g(info.srs_name, to_wgs);
  double x = 457842, y = 5439083;
  ASSERT_TRUE(g.transform_point(x, y));
  EXPECT_NEAR(x, 457842, 1.5);
  EXPECT_NEAR(y, 5439083, 1.5);
  // ... and into Gauss-Krüger zone 3, whose EPSG axis order is northing first: output stays easting first.
  CrsOptions to_gk;
  to_gk.target_srs = "EPSG:31467";
  WorkingFrame gk(info.srs_name, to_gk);
  x = 457842, y = 5439083;
  ASSERT_TRUE(gk.transform_point(x, y));
  EXPECT_NEAR(x, 3457900, 500);
  EXPECT_NEAR(y, 5440900, 2500);
}

TEST(WorkingFrame, PlateauLatLonGoesToUtm54NearTheWrittenPoint) {
  // "35.7559 139.5542 55.03": EPSG:6697 writes latitude first.
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  SourceInfo info;
  read_citygml(shared_data("citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml"), {},
               [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
  ASSERT_EQ(meshes.size(), 657u);
  ASSERT_TRUE(info.has_envelope);
  const Point3 written = meshes[0].vertices[0];
  ASSERT_NEAR(written.x, 35.8, 0.2);  // latitude
  ASSERT_NEAR(written.y, 139.6, 0.2); // longitude

  WorkingFrame f(info.srs_name);
  EXPECT_TRUE(f.source_geographic());
  EXPECT_FALSE(f.decided());
  f.decide((info.envelope_lower[0] + info.envelope_upper[0]) / 2, (info.envelope_lower[1] + info.envelope_upper[1]) / 2);
  EXPECT_EQ(f.working_crs().epsg, 32654);
  EXPECT_EQ(f.working_crs().definition, "EPSG:32654");
  ASSERT_TRUE(f.transform(meshes[0]));
  const Point3 utm = meshes[0].vertices[0];
  EXPECT_EQ(utm.z, written.z);

  // Independent check with PROJ: UTM 54N back to lat/lon lands on the written point (JGD2011 and
  // WGS 84 agree to well under a metre here).
  PJ_CONTEXT* ctx = proj_context_create();
  PJ* back = proj_create_crs_to_crs(ctx, "EPSG:32654", "EPSG:4326", nullptr);
  ASSERT_NE(back, nullptr);
  PJ_COORD c = proj_trans(back, PJ_FWD, proj_coord(utm.x, utm.y, 0, 0));  // EPSG:4326 out: lat, lon
  EXPECT_NEAR(c.v[0], written.x, 2e-5);
  EXPECT_NEAR(c.v[1], written.y, 2e-5);
  proj_destroy(back);
  proj_context_destroy(ctx);
  EXPECT_GT(utm.x, 300000);  // easting of a point west of 141°E in zone 54
  EXPECT_LT(utm.x, 500000);
  EXPECT_NEAR(utm.y, 3.96e6, 0.05e6);

  // Footprint: a building a few metres to tens of metres across, not degrees.
  FootprintResult fp = make_footprint(meshes[0]);
  ASSERT_TRUE(fp.ok) << fp.reason;
  double lo = 1e18, hi = -1e18;
  for (const Point2& q : fp.footprint.polygons[0].outer) lo = std::min(lo, q.x), hi = std::max(hi, q.x);
  EXPECT_GT(hi - lo, 1.0);
  EXPECT_LT(hi - lo, 300.0);
}

TEST(WorkingFrame, AxisOrderOverrideForFilesWritingLonLat) {
  // The Jefferson Building file says EPSG:4979 but writes lon, lat: the override puts it in Washington.
  CrsOptions east_first;
  east_first.source_axis = AxisOrder::EastNorth;
  WorkingFrame f("EPSG:4979", east_first);
  f.decide(-77.005, 38.888);
  EXPECT_EQ(f.working_crs().epsg, 32618);
  double x = -77.005, y = 38.888;
  ASSERT_TRUE(f.transform_point(x, y));
  EXPECT_NEAR(x, 325700, 1000);
  EXPECT_NEAR(y, 4306600, 1000);
}

TEST(WorkingFrame, GeographicLabelOnProjectedNumbersIsAClearError) {
  WorkingFrame f("EPSG:4326");
  try {
    f.decide(457842, 5439083);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("contradicts"), std::string::npos) << e.what();
  }
  Mesh m;
  m.add_face({{{457842, 5439083, 0}, {457852, 5439083, 0}, {457852, 5439093, 0}}}, SurfaceKind::Ground, 2);
  WorkingFrame g("EPSG:4326");
  EXPECT_THROW(g.transform(m), InputError);
}

TEST(WorkingFrame, UnknownCrsKeepsCoordinatesAndSaysSo) {
  for (const char* srs : {"", "#local-CRS-1", "not a crs at all"}) {
    WorkingFrame f(srs);
    EXPECT_FALSE(f.source_known()) << srs;
    EXPECT_FALSE(f.working_crs().known) << srs;
    EXPECT_TRUE(f.working_crs().wkt.empty()) << srs;
    ASSERT_EQ(f.notes().size(), 1u) << srs;
    EXPECT_NE(f.notes()[0].find("unknown"), std::string::npos);
    Mesh m;
    m.add_face({{{1, 2, 3}, {4, 5, 6}, {7, 8, 9}}}, SurfaceKind::Unknown, 1);
    ASSERT_TRUE(f.transform(m));
    EXPECT_EQ(m.vertices[0], (Point3{1, 2, 3}));
  }
  CrsOptions t;
  t.target_srs = "EPSG:32632";
  EXPECT_THROW(WorkingFrame("", t), InvalidArgument);
}

// Heights leave the frame in metres like x and y: a New York file in EPSG:2263 (US survey feet) writes a 118 m
// roof as 388.49; with a compound CRS the vertical part's unit decides (NAVD88 height (ftUS), EPSG:6360), also
// under a horizontal CRS in metres; heights of a CRS in metres are kept to the bit.
TEST(WorkingFrame, HeightsBecomeMetres) {
  constexpr double kFtUs = 1200.0 / 3937.0;
  struct Case {
    const char* srs;
    double x, y, factor;
  } cases[] = {
      {"EPSG:2263", 988000, 210000, kFtUs},
      {"EPSG:2263+6360", 988000, 210000, kFtUs},
      {"urn:ogc:def:crs,crs:EPSG::2263,crs:EPSG::6360", 988000, 210000, kFtUs},
      {"EPSG:32618+6360", 585000, 4512000, kFtUs},
      {"EPSG:2263+5703", 988000, 210000, 1.0},  // NAVD88 height in metres under a horizontal CRS in feet
      {"EPSG:25832", 457842, 5439083, 1.0},
      {"EPSG:25832+5783", 457842, 5439083, 1.0},
  };
  for (const Case& c : cases) {
    WorkingFrame f(c.srs);
    Mesh m;
    m.add_face({{{c.x, c.y, 388.49}, {c.x + 30, c.y, 388.49}, {c.x + 30, c.y + 30, 12.5}}}, SurfaceKind::Unknown, 1);
    ASSERT_TRUE(f.transform(m)) << c.srs;
    EXPECT_NEAR(m.vertices[0].z, 388.49 * c.factor, 1e-9) << c.srs;
    EXPECT_NEAR(m.vertices[2].z, 12.5 * c.factor, 1e-9) << c.srs;
    EXPECT_EQ(f.height_to_metre() == 1.0, c.factor == 1.0) << c.srs;
    if (c.factor == 1.0) EXPECT_EQ(m.vertices[0].z, 388.49) << c.srs;
  }
  // A horizontal CRS in metres with a vertical one in feet: x, y untouched, z converted.
  WorkingFrame f("EPSG:32618+6360");
  Mesh m;
  m.add_face({{{585000.25, 4512000.5, 100}, {585010, 4512000, 100}, {585010, 4512010, 0}}}, SurfaceKind::Unknown, 1);
  ASSERT_TRUE(f.transform(m));
  EXPECT_EQ(m.vertices[0].x, 585000.25);
  EXPECT_EQ(m.vertices[0].y, 4512000.5);
  EXPECT_EQ(f.working_crs().epsg, 32618);
}

TEST(WorkingFrame, TargetMustBeProjectedMetric) {
  CrsOptions t;
  t.target_srs = "EPSG:4326";
  EXPECT_THROW(WorkingFrame("EPSG:25832", t), InvalidArgument);
  t.target_srs = "EPSG:2263";  // NAD83 / New York Long Island (ftUS)
  EXPECT_THROW(WorkingFrame("EPSG:25832", t), InvalidArgument);
  t.target_srs = "no such thing";
  EXPECT_THROW(WorkingFrame("EPSG:25832", t), InvalidArgument);
}

TEST(WorkingFrame, UtmZones) {
  EXPECT_EQ(utm_epsg_for(139.55, 35.75), 32654);
  EXPECT_EQ(utm_epsg_for(131.8, 34.05), 32652);
  EXPECT_EQ(utm_epsg_for(-77.0, 38.9), 32618);
  EXPECT_EQ(utm_epsg_for(151.2, -33.9), 32756);
  EXPECT_EQ(utm_epsg_for(180.0, 0), 32660);
  EXPECT_EQ(utm_epsg_for(-180.0, 0), 32601);
}

}  // namespace
}  // namespace groundplan::gis

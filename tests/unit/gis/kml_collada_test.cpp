// SPDX-License-Identifier: MIT
// KML / KMZ + COLLADA reader and model placement (issue 6): every KML/KMZ/COLLADA sample in
// tests/data/ (and the third-party folder), small files made here for each feature (a unit cube in a KMZ at a known lon/lat,
// a Y_UP inch COLLADA, heading), and hostile input (escaping hrefs, URLs, zip bombs, broken indices).
// KMZ files are written by a minimal stored-zip writer below, so that hostile entry names and
// forged sizes can be made at will.
#include <groundplan/error.h>
#include <groundplan/footprint.h>
#include <groundplan/gis/collada.h>
#include <groundplan/gis/kml.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/placement.h>
#include <groundplan/gis/reader.h>

#include <gtest/gtest.h>
#include <proj.h>

#include "read_all.h"

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "test_support.h"

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;

using test::shared_data;

std::string pipeline_problems(const PipelineResult& r) {
  std::string all;
  for (const Problem& p : r.problems) all += p.code + ": " + p.reason + "\n";
  return all;
}

std::size_t count_code(const PipelineResult& r, const std::string& code) {
  std::size_t n = 0;
  for (const Problem& p : r.problems) n += p.code == code;
  return n;
}

// ---------------------------------------------------------------------------------------------------
// Helpers: stored zip writer, PROJ oracle (the temp folder: test::TempDir).


std::uint32_t crc32(const std::string& data) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (unsigned char b : data) c = table[(c ^ b) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

struct ZipEntry {
  std::string name, data;
  std::int64_t stated_size = -1;  // forged uncompressed size (local and central headers); -1 = true size
};

/// A zip with stored (uncompressed) entries: enough for GDAL's /vsizip/ and for forging.
std::string make_zip(const std::vector<ZipEntry>& entries) {
  std::string out, central;
  auto u16 = [](std::string& s, std::uint32_t v) { s.push_back(char(v & 0xFF)), s.push_back(char((v >> 8) & 0xFF)); };
  auto u32 = [&](std::string& s, std::uint32_t v) { u16(s, v & 0xFFFF), u16(s, v >> 16); };
  for (const ZipEntry& e : entries) {
    const std::uint32_t offset = static_cast<std::uint32_t>(out.size());
    const std::uint32_t crc = crc32(e.data);
    const std::uint32_t size = static_cast<std::uint32_t>(e.data.size());
    const std::uint32_t stated = e.stated_size < 0 ? size : static_cast<std::uint32_t>(e.stated_size);
    u32(out, 0x04034b50), u16(out, 20), u16(out, 0), u16(out, 0), u16(out, 0), u16(out, 0x21);
    u32(out, crc), u32(out, size), u32(out, stated);
    u16(out, static_cast<std::uint32_t>(e.name.size())), u16(out, 0);
    out += e.name + e.data;
    u32(central, 0x02014b50), u16(central, 20), u16(central, 20), u16(central, 0), u16(central, 0), u16(central, 0);
    u16(central, 0x21), u32(central, crc), u32(central, size), u32(central, stated);
    u16(central, static_cast<std::uint32_t>(e.name.size())), u16(central, 0), u16(central, 0), u16(central, 0);
    u16(central, 0), u32(central, 0), u32(central, offset);
    central += e.name;
  }
  const std::uint32_t cd_offset = static_cast<std::uint32_t>(out.size());
  out += central;
  u32(out, 0x06054b50), u16(out, 0), u16(out, 0), u16(out, static_cast<std::uint32_t>(entries.size()));
  u16(out, static_cast<std::uint32_t>(entries.size())), u32(out, static_cast<std::uint32_t>(central.size()));
  u32(out, cd_offset), u16(out, 0);
  return out;
}

/// PROJ's own lon/lat -> projected transformation (the oracle for placement).
std::array<double, 2> proj_forward(const std::string& target, double lon, double lat) {
  PJ_CONTEXT* ctx = proj_context_create();
  PJ* raw = proj_create_crs_to_crs(ctx, "EPSG:4326", target.c_str(), nullptr);
  PJ* op = proj_normalize_for_visualization(ctx, raw);
  const PJ_COORD c = proj_trans(op, PJ_FWD, proj_coord(lon, lat, 0, 0));
  proj_destroy(op);
  proj_destroy(raw);
  proj_context_destroy(ctx);
  return {c.xy.x, c.xy.y};
}

/// `s` with the first `from` replaced by `to` (the test fails loudly if `from` is missing).
void sub(std::string& s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  s.replace(at, from.size(), to);
}

struct Bbox {
  double x0 = 1e300, y0 = 1e300, z0 = 1e300, x1 = -1e300, y1 = -1e300, z1 = -1e300;
  void add(const Point3& p) {
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), z0 = std::min(z0, p.z);
    x1 = std::max(x1, p.x), y1 = std::max(y1, p.y), z1 = std::max(z1, p.z);
  }
  double dx() const { return x1 - x0; }
  double dy() const { return y1 - y0; }
  double dz() const { return z1 - z0; }
};
Bbox bbox(const Mesh& m) {
  Bbox b;
  for (std::uint32_t i : m.indices) b.add(m.vertices[i]);
  return b;
}

using test::Read;
using test::read;

// A unit cube, Z_UP metres, x,y in [-0.5, 0.5], z in [0, 1]: 6 quads in one polylist with
// VERTEX at offset 1 and NORMAL at offset 0 (stride 2), to test offsets.
std::string cube_dae(const std::string& unit = "1", const std::string& up = "Z_UP") {
  return R"(<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit meter=")" + unit + R"(" name="x"/><up_axis>)" + up + R"(</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="pos"><float_array id="pa" count="24">-0.5 -0.5 0  0.5 -0.5 0  0.5 0.5 0  -0.5 0.5 0
    -0.5 -0.5 1  0.5 -0.5 1  0.5 0.5 1  -0.5 0.5 1</float_array>
   <technique_common><accessor source="#pa" count="8" stride="3"><param name="X" type="float"/>
    <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
  <source id="nrm"><float_array id="na" count="3">0 0 1</float_array>
   <technique_common><accessor source="#na" count="1" stride="3"/></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#pos"/></vertices>
  <polylist count="6"><input semantic="NORMAL" source="#nrm" offset="0"/><input semantic="VERTEX" source="#v" offset="1"/>
   <vcount>4 4 4 4 4 4</vcount>
   <p>0 0 0 3 0 2 0 1  0 4 0 5 0 6 0 7  0 0 0 1 0 5 0 4  0 1 0 2 0 6 0 5  0 2 0 3 0 7 0 6  0 3 0 0 0 4 0 7</p>
  </polylist></mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene>
 </library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>)";
}

std::string model_kml(double lon, double lat, const std::string& href, const std::string& extra = "",
                      const std::string& ns = "http://www.opengis.net/kml/2.2") {
  char buf[64];
  std::string s = R"(<?xml version="1.0" encoding="UTF-8"?>
<kml xmlns=")" + ns + R"("><Document><Folder><Placemark id="pm"><name>cube</name><Model>)";
  std::snprintf(buf, sizeof buf, "%.10f", lon);
  s += std::string("<Location><longitude>") + buf + "</longitude>";
  std::snprintf(buf, sizeof buf, "%.10f", lat);
  s += std::string("<latitude>") + buf + "</latitude><altitude>0</altitude></Location>";
  s += extra + "<Link><href>" + href + "</href></Link></Model></Placemark></Folder></Document></kml>";
  return s;
}

// ---------------------------------------------------------------------------------------------------
// Real samples (counts: tests/data/kml-collada-macky-google/SOURCE.txt; Korea: the third-party folder).

TEST(KmlRealData, MackyKmzLandsInBoulderInUtm13WithInchesHonoured) {
  for (const char* kmz : {"macky-normal.kmz", "model-macky.kmz"}) {
    const Read r = read(shared_data(std::string("kml-collada-macky-google/") + kmz));
    ASSERT_EQ(r.meshes.size(), 1u) << kmz << "\n" << r.all();
    EXPECT_EQ(r.info.format, InputFormat::Kmz);
    EXPECT_TRUE(r.info.in_working_crs);
    EXPECT_EQ(r.info.working_crs.epsg, 32613) << r.info.working_crs.name;
    EXPECT_EQ(r.meshes[0].source_id, "model_4");
    const Bbox b = bbox(r.meshes[0]);
    const auto anchor = proj_forward("EPSG:32613", -105.2728, 40.0100);
    const double cx = (b.x0 + b.x1) / 2, cy = (b.y0 + b.y1) / 2;
    EXPECT_LT(std::hypot(cx - anchor[0], cy - anchor[1]), 100.0) << kmz << " centre " << cx << " " << cy;
    // Tens of metres: an auditorium. Without the inch unit (0.0254) it would be ~40x larger.
    EXPECT_GT(b.dx(), 20.0) << kmz;
    EXPECT_LT(b.dx(), 150.0) << kmz;
    EXPECT_GT(b.dy(), 20.0) << kmz;
    EXPECT_LT(b.dy(), 150.0) << kmz;
    EXPECT_GT(b.dz(), 10.0) << kmz;
    EXPECT_LT(b.dz(), 80.0) << kmz;
    EXPECT_EQ(r.info.kml.network_links, 0u);
  }
}

TEST(KmlRealData, SharedTexturesKmzHasTwoModelsInOneFolder) {
  const Read r = read(shared_data("kml-collada-macky-google/shared-textures.kmz"));
  ASSERT_EQ(r.meshes.size(), 2u) << r.all();
  EXPECT_EQ(r.meshes[0].source_id, "building");
  EXPECT_EQ(r.meshes[1].source_id, "wall");
  EXPECT_EQ(r.info.working_crs.epsg, 32610);
  const auto anchor = proj_forward("EPSG:32610", -122.451703589982, 37.80564180933);
  for (const Mesh& m : r.meshes) {
    const Bbox b = bbox(m);
    EXPECT_LT(std::hypot((b.x0 + b.x1) / 2 - anchor[0], (b.y0 + b.y1) / 2 - anchor[1]), 50.0) << m.source_id;
    EXPECT_LT(std::max(b.dx(), b.dy()), 60.0) << m.source_id;
  }
}

TEST(KmlRealDataThirdParty, KoreaKmlBesideDaeThreeBuildings) {
  const std::string dir = shared_data("kml-collada-korea-mago/sample-kml/");
  GROUNDPLAN_SKIP_IF_MISSING(dir);
  for (const char* kml : {"a_bd001.kml", "a_bd002.kml", "a_bd003.kml"}) {
    const Read r = read(dir + kml);
    ASSERT_EQ(r.meshes.size(), 1u) << kml << "\n" << r.all();
    EXPECT_EQ(r.info.working_crs.epsg, 32652);
    const Bbox b = bbox(r.meshes[0]);
    // About 38 m x 32 m, z 0..91 m; "centimeter" in the unit's name, meter="1.0" trusted.
    EXPECT_GT(b.dx(), 20.0) << kml;
    EXPECT_LT(b.dx(), 60.0) << kml;
    EXPECT_GT(b.dy(), 20.0) << kml;
    EXPECT_LT(b.dy(), 60.0) << kml;
    EXPECT_NEAR(b.dz(), 91.0, 5.0) << kml;
  }
}

TEST(KmlRealDataThirdParty, KoreaErrorCaseOneModelAndTwoMissingLinks) {
  const std::string dir = shared_data("kml-collada-korea-mago/sample-kml-error-case/");
  GROUNDPLAN_SKIP_IF_MISSING(dir);
  std::size_t meshes = 0, missing = 0;
  for (const char* kml : {"a_bd001.kml", "a_bd002.kml", "a_bd003.kml"}) {
    const Read r = read(dir + kml);
    meshes += r.meshes.size();
    missing += r.count("LINK_TARGET_NOT_FOUND");
    for (const Problem& p : r.problems)
      if (p.code == "LINK_TARGET_NOT_FOUND") {
        EXPECT_NE(p.reason.find("link target not found"), std::string::npos);
      }
  }
  EXPECT_EQ(meshes, 1u);
  EXPECT_EQ(missing, 2u);
}

TEST(KmlRealData, StandaloneDaeNeedsAnOrigin) {
  const std::string dae = shared_data("kml-collada-macky-google/standalone_dae/cu_macky/CU Macky.dae");
  try {
    read(dae);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--origin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("CU Macky.dae"), std::string::npos) << e.what();
  }
  ReadOptions opt;
  opt.origin = "-105.272774533734,40.009993372683,0";
  const Read r = read(dae, opt);
  ASSERT_EQ(r.meshes.size(), 1u) << r.all();
  const Bbox b = bbox(r.meshes[0]);
  EXPECT_GT(b.dx(), 20.0);
  EXPECT_LT(b.dx(), 150.0);
}

TEST(KmlRealData, PipelineEndToEndOnKmz) {
  PipelineOptions options;
  PipelineResult r;
  auto problems = [&] { return pipeline_problems(r); };
  auto count = [&](const std::string& code) { return count_code(r, code); };
  // Macky: placed and in the working CRS; its SketchUp triangle soup is the footprint stage's
  // business: a footprint or a footprint Problem, never lost.
  options.inputs = {shared_data("kml-collada-macky-google/macky-normal.kmz")};
  r = run_pipeline(options);
  EXPECT_EQ(r.buildings_read, 1u);
  EXPECT_EQ(r.crs_name, "EPSG:32613");
  EXPECT_FALSE(r.crs_wkt.empty());
  std::size_t footprint_problems = 0;
  // A kept shadow footprint comes with a FOOTPRINT_SHADOW note (issue 21), one closed in plan with a
  // FOOTPRINT_CLOSED_IN_PLAN note; neither drops anything.
  for (const Problem& p : r.problems)
    footprint_problems += p.stage == "footprint" && p.source_id == "model_4" && p.code != "FOOTPRINT_SHADOW" &&
                          p.code != "FOOTPRINT_CLOSED_IN_PLAN";
  EXPECT_EQ(r.footprints.size() + footprint_problems, 1u) << problems();
  EXPECT_EQ(count("FOOTPRINT_SHADOW"), r.footprints.size() == 1 && r.footprints[0].method == "decomposition-shadow" ? 1u : 0u)
      << problems();
  // Issue 21: Macky's walls give its footprint (their lower boundary closed in plan across the 7-8 cm
  // gaps between its SketchUp parts), not the shadow.
  ASSERT_EQ(r.footprints.size(), 1u) << problems();
  EXPECT_EQ(r.footprints[0].method, "decomposition") << problems();
  EXPECT_EQ(count("FOOTPRINT_CLOSED_IN_PLAN"), 1u) << problems();
}

TEST(KmlRealDataThirdParty, PipelineEndToEndOnKmlFolders) {
  PipelineOptions options;
  PipelineResult r;
  auto problems = [&] { return pipeline_problems(r); };
  auto count = [&](const std::string& code) { return count_code(r, code); };
  GROUNDPLAN_SKIP_IF_MISSING(shared_data("kml-collada-korea-mago/sample-kml"));
  options.inputs = {shared_data("kml-collada-korea-mago/sample-kml")};
  r = run_pipeline(options);
  EXPECT_EQ(r.buildings_read, 3u) << "3 KMLs; the .dae beside them are not inputs of their own";
  EXPECT_EQ(r.footprints.size(), 3u) << problems();
  EXPECT_GE(r.plans.size(), 1u);
  EXPECT_EQ(r.crs_name, "EPSG:32652");
  double area = 0;
  for (const GroundPlan& g : r.plans) area += g.area_m2;
  EXPECT_GT(area, 3 * 300.0);
  EXPECT_LT(area, 3 * 1500.0);

  options.inputs = {shared_data("kml-collada-korea-mago/sample-kml-error-case")};
  r = run_pipeline(options);
  EXPECT_EQ(r.buildings_read, 3u) << "a building given up by the reader still counts as read (issue 8)";
  EXPECT_EQ(r.buildings_dropped, 2u);
  EXPECT_EQ(r.footprints.size(), 1u) << problems();
  EXPECT_EQ(count("LINK_TARGET_NOT_FOUND"), 2u);
  EXPECT_EQ(r.crs_name, "EPSG:32652");
}

// ---------------------------------------------------------------------------------------------------
// Small files made here.

TEST(KmlPlacement, UnitCubeInKmzLandsOnProjsAnchorWithin1cm) {
  test::TempDir tmp("groundplan_kml_test");
  const double lon = 8.4037, lat = 49.0069;  // Karlsruhe, 0.6° west of UTM 32N's central meridian
  const std::string kmz = tmp.file("cube.kmz", make_zip({{"doc.kml", model_kml(lon, lat, "models/cube.dae")},
                                                         {"models/cube.dae", cube_dae()}}));
  const Read r = read(kmz);
  ASSERT_EQ(r.meshes.size(), 1u) << r.all();
  EXPECT_EQ(r.meshes[0].source_id, "pm");
  EXPECT_EQ(r.info.working_crs.epsg, 32632);
  const FootprintResult fp = make_footprint(r.meshes[0]);
  ASSERT_TRUE(fp.ok) << fp.reason;
  ASSERT_EQ(fp.footprint.polygons.size(), 1u);
  double cx = 0, cy = 0;
  const auto& ring = fp.footprint.polygons[0].outer;
  for (const auto& p : ring) cx += p.x, cy += p.y;
  cx /= static_cast<double>(ring.size());
  cy /= static_cast<double>(ring.size());
  const auto anchor = proj_forward("EPSG:32632", lon, lat);
  const double err = std::hypot(cx - anchor[0], cy - anchor[1]);
  EXPECT_LT(err, 0.01) << "footprint centre " << cx << " " << cy << " vs PROJ " << anchor[0] << " " << anchor[1];
  char err_text[32];
  std::snprintf(err_text, sizeof err_text, "%.3e", err);
  RecordProperty("anchor_error_m", err_text);
  double area2 = 0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const auto& a = ring[i];
    const auto& b = ring[(i + 1) % ring.size()];
    area2 += a.x * b.y - b.x * a.y;
  }
  EXPECT_NEAR(std::fabs(area2) / 2, 0.9996 * 0.9996, 0.01);
  // Also through a plain .kml beside the .dae and the old Google namespace.
  tmp.file("plain/m/cube.dae", cube_dae());
  const std::string kml = tmp.file("plain/doc.kml", model_kml(lon, lat, "m/cube.dae", "", "http://earth.google.com/kml/2.1"));
  const Read r2 = read(kml);
  ASSERT_EQ(r2.meshes.size(), 1u) << r2.all();
  EXPECT_EQ(r2.meshes[0].vertices, r.meshes[0].vertices);
}

TEST(KmlPlacement, Heading90TurnsNorthToEast) {
  test::TempDir tmp("groundplan_kml_test");
  // A 2 m (x) by 1 m (y) box with a corner at the anchor; on UTM 32N's central meridian (no grid
  // convergence). Heading 90 is clockwise: model x (east) goes south, model y (north) goes east.
  std::string dae = cube_dae();
  sub(dae, "-0.5 -0.5 0  0.5 -0.5 0  0.5 0.5 0  -0.5 0.5 0", "0 0 0  2 0 0  2 1 0  0 1 0");
  sub(dae, "-0.5 -0.5 1  0.5 -0.5 1  0.5 0.5 1  -0.5 0.5 1", "0 0 1  2 0 1  2 1 1  0 1 1");
  tmp.file("box.dae", dae);
  const double lon = 9.0, lat = 48.0;
  const auto anchor = proj_forward("EPSG:32632", lon, lat);
  for (double heading : {0.0, 90.0}) {
    const std::string kml = tmp.file("h.kml", model_kml(lon, lat, "box.dae",
                                                        "<Orientation><!-- c --><heading>" + std::to_string(heading) +
                                                            "</heading></Orientation><altitudeMode>absolute</altitudeMode>"));
    const Read r = read(kml);
    ASSERT_EQ(r.meshes.size(), 1u) << r.all();
    const Bbox b = bbox(r.meshes[0]);
    const double e0 = b.x0 - anchor[0], e1 = b.x1 - anchor[0], n0 = b.y0 - anchor[1], n1 = b.y1 - anchor[1];
    const double k = 0.9996;  // UTM scale on the central meridian
    if (heading == 0) {
      EXPECT_NEAR(e0, 0, 0.005);
      EXPECT_NEAR(e1, 2 * k, 0.005);
      EXPECT_NEAR(n0, 0, 0.005);
      EXPECT_NEAR(n1, 1 * k, 0.005);
    } else {
      EXPECT_NEAR(e0, 0, 0.005);
      EXPECT_NEAR(e1, 1 * k, 0.005);
      EXPECT_NEAR(n0, -2 * k, 0.005);
      EXPECT_NEAR(n1, 0, 0.005);
    }
  }
}

TEST(KmlPlacement, ScaleAndOrientationMatrixOrder) {
  ModelPlacement p;
  p.heading_deg = 90;
  p.scale_x = 2;
  const auto m = model_matrix(p);
  // (1, 0, 0) scaled to (2, 0, 0), then clockwise 90° seen from above: east -> south.
  EXPECT_NEAR(m[0] * 1, 0, 1e-12);
  EXPECT_NEAR(m[4] * 1, -2, 1e-12);
  EXPECT_THROW(parse_origin("49.0"), InvalidArgument);
  EXPECT_THROW(parse_origin("200,10"), InvalidArgument);
  EXPECT_NEAR(parse_origin(" 8.5, 49.1 ,110").alt_m, 110, 1e-12);
}

TEST(Collada, YUpInchesBecomeZUpMetres) {
  // Box 100 in (x) by 200 in (y: up in Y_UP) by 50 in (z: toward the viewer = south).
  std::string dae = cube_dae("0.0254", "Y_UP");
  sub(dae, "-0.5 -0.5 0  0.5 -0.5 0  0.5 0.5 0  -0.5 0.5 0", "0 0 0  100 0 0  100 0 50  0 0 50");
  sub(dae, "-0.5 -0.5 1  0.5 -0.5 1  0.5 0.5 1  -0.5 0.5 1", "0 200 0  100 200 0  100 200 50  0 200 50");
  std::vector<Problem> problems;
  ColladaInfo info;
  const Mesh m = read_collada_buffer(dae, "yup.dae", "box", {}, problems, info);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(info.up_axis, "Y_UP");
  EXPECT_DOUBLE_EQ(info.unit_m, 0.0254);
  ASSERT_EQ(m.faces.size(), 6u);
  const Bbox b = bbox(m);
  EXPECT_NEAR(b.x0, 0, 1e-9);
  EXPECT_NEAR(b.x1, 2.54, 1e-9);
  EXPECT_NEAR(b.y0, -1.27, 1e-9);
  EXPECT_NEAR(b.y1, 0, 1e-9);
  EXPECT_NEAR(b.z0, 0, 1e-9);
  EXPECT_NEAR(b.z1, 5.08, 1e-9);
}

TEST(Collada, NodeTransformsInstanceNodesAndPrimitives) {
  // library_nodes node "unit" holds a triangle; the scene instantiates it twice: once translated
  // (10, 0, 0) after a 90° rotation about z, once scaled by 2 through a matrix.
  const std::string dae = R"(<COLLADA xmlns="http://www.collada.org/2008/03/COLLADASchema" version="1.5.0">
 <asset><up_axis>Z_UP</up_axis></asset>
 <library_geometries><geometry id="t"><mesh>
  <source id="p"><float_array id="a" count="12">0 0 0 1 0 0 0 1 0 1 1 0</float_array>
   <technique_common><accessor source="#a" count="4" stride="3"/></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
  <polygons count="1"><input semantic="VERTEX" source="#v" offset="0"/><ph><p>0 1 3 2</p><h>0 1 3</h></ph></polygons>
  <trifans count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 3 2</p></trifans>
 </mesh></geometry></library_geometries>
 <library_nodes><node id="unit"><instance_geometry url="#t"/></node></library_nodes>
 <library_visual_scenes><visual_scene id="s">
  <node><translate>10 0 0</translate><rotate>0 0 1 90</rotate><instance_node url="#unit"/></node>
  <node><matrix>2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1</matrix><instance_node url="#unit"/></node>
 </visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>)";
  std::vector<Problem> problems;
  ColladaInfo info;
  const Mesh m = read_collada_buffer(dae, "t.dae", "t", {}, problems, info);
  EXPECT_TRUE(problems.empty()) << problems.front().reason;
  EXPECT_EQ(info.node_instances, 2u);
  EXPECT_EQ(info.geometry_instances, 2u);
  ASSERT_EQ(m.faces.size(), 2u * (1 + 1 + 2));  // triangle, polygon with a hole, fan of 2
  EXPECT_EQ(m.faces[1].ring_count, 2u);
  // First instance: (1, 0, 0) -> rotate 90° -> (0, 1, 0) -> translate -> (10, 1, 0).
  const Point3 p = m.vertices[m.indices[m.ring_offsets[0] + 1]];
  EXPECT_NEAR(p.x, 10, 1e-12);
  EXPECT_NEAR(p.y, 1, 1e-12);
  const Point3 q = m.vertices[m.indices[m.ring_offsets[m.faces[4].first_ring] + 1]];
  EXPECT_NEAR(q.x, 2, 1e-12);
  EXPECT_NEAR(q.y, 0, 1e-12);
}

TEST(Kml, OrderCommentsNamespacesMultiGeometryAndIds) {
  test::TempDir tmp("groundplan_kml_test");
  tmp.file("c.dae", cube_dae());
  const std::string kml = tmp.file("k.kml", R"(<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Folder><Folder>
<Placemark><name>two</name><LookAt><longitude>1</longitude><latitude>1</latitude><heading>45</heading></LookAt>
<MultiGeometry>
 <Model><Link><href>c.dae</href></Link><Scale><z>2</z><!-- doubled --><x>1</x></Scale>
  <Location><latitude>37.6<!-- x -->2</latitude><longitude>127.17</longitude></Location><altitudeMode>relativeToGround</altitudeMode></Model>
 <Model id="m2"><Location><longitude>127.1701</longitude><latitude>37.62</latitude></Location><Link><href>./c.dae</href></Link></Model>
</MultiGeometry></Placemark>
<Placemark id="nolink"><Model><Location><longitude>127</longitude><latitude>37</latitude></Location></Model></Placemark>
<Placemark id="noloc"><Model><Link><href>c.dae</href></Link></Model></Placemark>
</Folder></Folder></Document></kml>)");
  const Read r = read(kml);
  ASSERT_EQ(r.meshes.size(), 2u) << r.all();
  EXPECT_EQ(r.meshes[0].source_id, "two");
  EXPECT_EQ(r.meshes[1].source_id, "m2") << "a Model's own id names it";
  EXPECT_EQ(r.meshes[0].name, "two");
  EXPECT_NEAR(bbox(r.meshes[0]).dz(), 2.0, 1e-3) << "Scale z read after a comment, out of order";
  // 1.02 from UTM 52N's grid convergence (-1.1° here); the LookAt's heading 45 would give 1.41.
  EXPECT_NEAR(bbox(r.meshes[0]).dx(), 1.0, 0.05) << "LookAt heading must not rotate the model";
  // Latitude "37.6<!-- x -->2" is 37.62: both models within a few hundred metres of each other.
  const Bbox b0 = bbox(r.meshes[0]), b1 = bbox(r.meshes[1]);
  EXPECT_LT(std::hypot(b0.x0 - b1.x0, b0.y0 - b1.y0), 300.0);
  EXPECT_EQ(r.count("NO_LINK"), 1u);
  EXPECT_EQ(r.count("NO_LOCATION"), 1u);
  EXPECT_EQ(r.info.kml.placemarks, 3u);
}

TEST(Kml, HrefResolution) {
  std::string out;
  EXPECT_EQ(resolve_href("a/b.dae", "", out), HrefStatus::Ok);
  EXPECT_EQ(out, "a/b.dae");
  EXPECT_EQ(resolve_href("../b.dae", "sub/", out), HrefStatus::Ok);
  EXPECT_EQ(out, "b.dae");
  EXPECT_EQ(resolve_href("models\\x%20y.dae", "", out), HrefStatus::Ok);
  EXPECT_EQ(out, "models/x y.dae");
  EXPECT_EQ(resolve_href("../../etc/passwd", "", out), HrefStatus::Escapes);
  EXPECT_EQ(resolve_href("a/../../b", "", out), HrefStatus::Escapes);
  EXPECT_EQ(resolve_href("%2e%2e/%2e%2e/etc/passwd", "x/", out), HrefStatus::Escapes);
  EXPECT_EQ(resolve_href("/etc/passwd", "", out), HrefStatus::Absolute);
  EXPECT_EQ(resolve_href("C:/x.dae", "", out), HrefStatus::Absolute);
  EXPECT_EQ(resolve_href("http://example.com/m.dae", "", out), HrefStatus::Remote);
  EXPECT_EQ(resolve_href("file:///etc/passwd", "", out), HrefStatus::Remote);
  EXPECT_EQ(resolve_href("  ", "", out), HrefStatus::Empty);
  EXPECT_EQ(resolve_href("a%00b", "", out), HrefStatus::Invalid);
}

// ---------------------------------------------------------------------------------------------------
// Hostile input: a Problem or an InputError, bounded by limits, nothing outside the input opened.

TEST(KmlHostile, EscapingAbsoluteAndRemoteLinksAreProblems) {
  test::TempDir tmp("groundplan_kml_test");
  const std::string doc = R"(<kml xmlns="http://www.opengis.net/kml/2.2"><Document>
<Placemark id="escape"><Model><Location><longitude>8</longitude><latitude>49</latitude></Location>
 <Link><href>../../etc/passwd</href></Link></Model></Placemark>
<Placemark id="absolute"><Model><Location><longitude>8</longitude><latitude>49</latitude></Location>
 <Link><href>/etc/passwd</href></Link></Model></Placemark>
<Placemark id="remote"><Model><Location><longitude>8</longitude><latitude>49</latitude></Location>
 <Link><href>http://127.0.0.1:9/m.dae</href></Link></Model></Placemark>
<NetworkLink><Link><href>https://example.com/more.kml</href></Link></NetworkLink>
</Document></kml>)";
  // The archive even holds an entry named ../../etc/passwd: never opened.
  const std::string kmz = tmp.file("evil.kmz", make_zip({{"doc.kml", doc}, {"../../etc/passwd", cube_dae()}}));
  const Read r = read(kmz);
  EXPECT_TRUE(r.meshes.empty());
  EXPECT_EQ(r.count("LINK_OUTSIDE_INPUT"), 2u) << r.all();
  EXPECT_EQ(r.count("REMOTE_LINK_NOT_FETCHED"), 1u) << r.all();
  EXPECT_EQ(r.count("NETWORK_LINK_NOT_FOLLOWED"), 1u) << r.all();
  // The same beside the KML on disk, plus a symbolic link that leaves the folder.
  tmp.file("outside/c.dae", cube_dae());
  const std::string kml = tmp.file("in/doc.kml", doc);
  fs::create_symlink(tmp.path / "outside", tmp.path / "in" / "link");
  const std::string kml2 = tmp.file("in/doc2.kml", model_kml(8, 49, "link/c.dae"));
  const std::string kml3 = tmp.file("in/doc3.kml", model_kml(8, 49, "../outside/c.dae"));
  EXPECT_EQ(read(kml).count("LINK_OUTSIDE_INPUT"), 2u);
  EXPECT_EQ(read(kml2).count("LINK_OUTSIDE_INPUT"), 1u);
  EXPECT_EQ(read(kml3).count("LINK_OUTSIDE_INPUT"), 1u);
}

// Bounded by the unpacked bytes the reader counts (KmlInfo::bytes), not by the clock.
TEST(KmlHostile, ZipBombsAreRefusedWithinTheByteLimits) {
  test::TempDir tmp("groundplan_kml_test");
  // A .dae whose stated size is 2 GiB (forged central directory): refused before reading.
  const std::string forged = tmp.file("forged.kmz", make_zip({{"doc.kml", model_kml(8, 49, "m.dae")},
                                                              {"m.dae", cube_dae(), std::int64_t{2} << 30}}));
  Read r = read(forged);
  EXPECT_TRUE(r.meshes.empty());
  ASSERT_EQ(r.count("BAD_MODEL"), 1u) << r.all();
  EXPECT_NE(r.all().find("zip bomb"), std::string::npos) << r.all();
  EXPECT_LT(r.info.kml.bytes, 4096u);  // the doc.kml only: nothing of the 2 GiB
  // doc.kml itself stated at 3 GiB: the whole input is refused.
  const std::string forged_kml = tmp.file("forged2.kmz", make_zip({{"doc.kml", model_kml(8, 49, "m.dae"),
                                                                    std::int64_t{3} << 30}}));
  EXPECT_THROW(read(forged_kml), InputError);
  // Real bytes over the limits (lowered here to keep the test fast): per entry, then in total.
  std::string big = cube_dae();
  big.insert(big.find("<asset>"), "<!--" + std::string(3 << 20, ' ') + "-->");
  const std::string entry = tmp.file("big.kmz", make_zip({{"doc.kml", model_kml(8, 49, "m.dae")}, {"m.dae", big}}));
  ReadOptions opt;
  opt.kml.max_entry_bytes = 2 << 20;
  r = read(entry, opt);
  EXPECT_EQ(r.count("BAD_MODEL"), 1u) << r.all();
  EXPECT_LT(r.info.kml.bytes, opt.kml.max_entry_bytes);  // the doc.kml only: the entry was never unpacked
  std::string many_doc = R"(<kml><Document>)";
  std::vector<ZipEntry> many;
  for (int i = 0; i < 4; ++i) {
    many_doc += "<Placemark><Model><Location><longitude>8</longitude><latitude>49</latitude></Location><Link><href>m" +
                std::to_string(i) + ".dae</href></Link></Model></Placemark>";
    many.push_back({"m" + std::to_string(i) + ".dae", big});
  }
  many.insert(many.begin(), ZipEntry{"doc.kml", many_doc + "</Document></kml>"});
  opt.kml.max_entry_bytes = 4 << 20;
  opt.kml.max_total_bytes = 8 << 20;
  r = read(tmp.file("many.kmz", make_zip(many)), opt);
  EXPECT_EQ(r.meshes.size(), 2u) << r.all();
  EXPECT_EQ(r.count("BAD_MODEL"), 2u) << r.all();
  EXPECT_LE(r.info.kml.bytes, opt.kml.max_total_bytes);
}

TEST(KmlHostile, NotAZipNotXmlAndEntities) {
  test::TempDir tmp("groundplan_kml_test");
  try {
    read(tmp.file("fake.kmz", "this is not a zip archive at all"));
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a zip"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read(tmp.file("empty.kmz", make_zip({{"readme.txt", "x"}}))), InputError);
  EXPECT_THROW(read(tmp.file("trunc.kml", "<kml><Document><Placemark>")), InputError);
  const std::string laughs = R"(<?xml version="1.0"?><!DOCTYPE kml [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]>
<kml><Document><name>&b;</name></Document></kml>)";
  try {
    read(tmp.file("laughs.kml", laughs));
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("entity"), std::string::npos) << e.what();
  }
  std::string deep = "<kml>";
  for (int i = 0; i < 1000; ++i) deep += "<Folder>";
  EXPECT_THROW(read(tmp.file("deep.kml", deep)), InputError);
}

TEST(ColladaHostile, BrokenIndicesAndCyclesAreProblems) {
  std::string dae = cube_dae();
  // One quad points at vertex 99 (of 8), another is cut short; the other four faces stay.
  sub(dae, "0 0 0 3 0 2 0 1", "0 0 0 3 0 99 0 1");
  sub(dae, "<vcount>4 4 4 4 4 4</vcount>", "<vcount>4 4 4 4 4 9</vcount>");
  std::vector<Problem> problems;
  ColladaInfo info;
  Mesh m = read_collada_buffer(dae, "bad.dae", "bad", {}, problems, info);
  EXPECT_EQ(m.faces.size(), 4u);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].code, "BAD_INDICES");
  for (std::uint32_t i : m.indices) EXPECT_LT(i, m.vertices.size());
  // Negative and non-numeric indices, an accessor longer than its array.
  std::string neg = cube_dae();
  sub(neg, "0 0 0 3 0 2 0 1", "0 0 0 -3 0 2 0 1");
  problems.clear();
  m = read_collada_buffer(neg, "neg.dae", "neg", {}, problems, info);
  EXPECT_TRUE(m.faces.empty());
  EXPECT_GE(problems.size(), 1u);
  std::string acc = cube_dae();
  sub(acc, "count=\"8\" stride=\"3\"", "count=\"80\" stride=\"3\"");
  problems.clear();
  m = read_collada_buffer(acc, "acc.dae", "acc", {}, problems, info);
  EXPECT_TRUE(m.faces.empty());
  EXPECT_FALSE(problems.empty());
  // instance_node cycle: bounded by the depth limit, a Problem.
  std::string cyc = cube_dae();
  cyc.replace(cyc.find("<library_visual_scenes>"), 0,
              R"(<library_nodes><node id="a"><instance_geometry url="#g"/><instance_node url="#b"/></node>
               <node id="b"><instance_node url="#a"/><instance_node url="#a"/></node></library_nodes>)");
  sub(cyc, "<node id=\"n\">", "<node id=\"n\"><instance_node url=\"#a\"/>");
  problems.clear();
  m = read_collada_buffer(cyc, "cyc.dae", "cyc", {}, problems, info);  // bounded by the limits below, not the clock
  bool bounded = false;
  for (const Problem& p : problems) bounded |= p.code == "INSTANCE_DEPTH" || p.code == "TOO_MANY_INSTANCES" || p.code == "TOO_MANY_VERTICES";
  EXPECT_TRUE(bounded);
  EXPECT_THROW(read_collada_buffer("<kml/>", "x.dae", "x", {}, problems, info), InputError);
}

}  // namespace
}  // namespace groundplan::gis

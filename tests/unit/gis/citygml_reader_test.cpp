// SPDX-License-Identifier: MIT
// CityGML reader (issue 6): every real sample (tests/data/ and the third-party folder), small inline documents for each
// feature, and hostile / broken input.
#include <groundplan/error.h>
#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>

#include <gtest/gtest.h>

#include "test_support.h"

#include <fstream>
#include <map>
#include <sstream>

namespace groundplan::gis {
namespace {

struct ReadResult {
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  SourceInfo info;
  std::size_t count(const std::string& code) const {
    std::size_t n = 0;
    for (const Problem& p : problems) n += p.code == code;
    return n;
  }
  const Mesh* find(const std::string& id) const {
    for (const Mesh& m : meshes)
      if (m.source_id == id) return &m;
    return nullptr;
  }
};

ReadResult read_file(const std::string& path, const CityGmlOptions& opt = {}) {
  ReadResult r;
  read_citygml(path, opt, [&](Mesh&& m) { r.meshes.push_back(std::move(m)); }, r.problems, r.info);
  return r;
}

ReadResult read_xml(const std::string& xml, const CityGmlOptions& opt = {}) {
  ReadResult r;
  read_citygml_buffer(xml, "inline.gml", opt, [&](Mesh&& m) { r.meshes.push_back(std::move(m)); }, r.problems,
                      r.info);
  return r;
}

using test::shared_data;

std::size_t faces_of_kind(const Mesh& m, SurfaceKind k) {
  std::size_t n = 0;
  for (const MeshFace& f : m.faces) n += f.kind == k;
  return n;
}

// ---------------------------------------------------------------------------------------------------
// Every real CityGML sample (tests/data/ and the third-party folder): counts as their SOURCE.txt states them.

struct SampleCase {
  const char* file;
  std::size_t buildings, parts, meshes, footprints;
  std::size_t read_problems;  // Problems from the reader (codes checked where non-zero)
};

// In the repository (tests/data/).
const std::vector<SampleCase> kSamples = {
    {"citygml-fzkhaus-denhaag-misc/TUM-Main-Entrance.gml", 1, 0, 1, 1, 0},
    {"citygml1-berlin-lod2-libcitygml/b1_lod2_cs_w_sem.gml", 1, 0, 1, 1, 0},
    {"citygml1-berlin-lod2-libcitygml/b1_lod2_s.gml", 1, 0, 1, 1, 0},
    {"citygml1-niedersachsen-lod1-4tiles/LoD1_24065860_2_2021-01-25.gml", 7, 1, 8, 8, 0},
    {"citygml1-niedersachsen-lod1-4tiles/LoD1_24065862_2_2021-01-25.gml", 80, 24, 104, 104, 0},
    {"citygml1-niedersachsen-lod1-4tiles/LoD1_24085860_2_2021-01-25.gml", 78, 59, 137, 137, 0},
    {"citygml1-niedersachsen-lod1-4tiles/LoD1_24085862_2_2021-01-25.gml", 243, 175, 418, 418, 0},
    {"citygml2-plateau-japan-lod1/51311568_bldg_6697_op.gml", 225, 0, 225, 225, 0},
    {"citygml2-plateau-japan-lod1/53392547_bldg_6697_op2.gml", 25, 0, 25, 25, 0},
    {"citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml", 657, 0, 657, 657, 0},
};
// Not redistributable: the third-party folder (ThirdParty tests).
const std::vector<SampleCase> kThirdPartySamples = {
    {"citygml-citygml4j-samples/lod2_buildings_v3.gml", 100, 0, 100, 100, 0},
    {"citygml-citygml4j-samples/lod3_building_v2.gml", 1, 0, 1, 1, 0},
    {"citygml-fzkhaus-denhaag-misc/DenHaag_1BwBP.gml", 1, 6, 6, 6, 0},
    {"citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD1-KIT-IAI-KHH-B36-V1__v3.gml", 1, 0, 1, 1, 0},
    {"citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml", 1, 0, 1, 1, 0},
    {"citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD3-KIT-IAI-KHH-B36-V1__v3.gml", 1, 0, 1, 1, 0},
    {"citygml-fzkhaus-denhaag-misc/FZK-Haus_full.gml", 0, 0, 0, 0, 1},  // IndoorGML: NOT_CITYGML
    {"citygml-fzkhaus-denhaag-misc/dh_1.gml", 1, 6, 6, 6, 0},
    {"citygml-ogc-spec-samples/BuildingUnits_Storeys_xlink.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/JeffersonBuilding_CityGML3.0_LOD1_with_xAL3_CommonTypes.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/LocalCRS_CityGML3.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml", 1, 0, 1, 1, 1},  // a 2-point ring
    {"citygml-ogc-spec-samples/plateau_53394517_bldg_6697_2_op_CityGML2.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/plateau_53394517_bldg_6697_2_op_CityGML3.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v2_Building_LOD0-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v2_Building_LOD1-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v2_Building_LOD1-LocalEngineeringCRS.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v2_Building_LOD2-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v2_Building_LOD3-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v2_Building_LOD4-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v2_Building_and_garage_LOD2-EPSG25832.gml", 1, 1, 2, 2, 0},
    {"citygml-ogc-spec-samples/v3_Building_LOD0-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v3_Building_LOD1-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v3_Building_LOD1-LocalEngineeringCRS.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v3_Building_LOD2-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v3_Building_LOD3-EPSG25832.gml", 1, 0, 1, 1, 0},
    {"citygml-ogc-spec-samples/v3_Building_and_garage_LOD2-EPSG25832.gml", 1, 1, 2, 2, 0},
    {"citygml1-berlin-lod2-libcitygml/FZK-Haus-LoD0-KIT-IAI-KHH-B36-V1.gml", 1, 0, 1, 1, 0},
    {"citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml", 61, 0, 61, 61, 0},
};

/// Each file reads with its stated counts, and every mesh gives a footprint in the working frame.
void expect_stated_counts(const std::vector<SampleCase>& samples, std::size_t expected_meshes) {
  std::size_t total_meshes = 0, total_footprints = 0;
  for (const SampleCase& c : samples) {
    SCOPED_TRACE(c.file);
    ReadResult r = read_file(shared_data(c.file));
    EXPECT_EQ(r.info.buildings, c.buildings);
    EXPECT_EQ(r.info.building_parts, c.parts);
    EXPECT_EQ(r.meshes.size(), c.meshes);
    EXPECT_EQ(r.info.meshes, c.meshes);
    EXPECT_EQ(r.problems.size(), c.read_problems);
    EXPECT_EQ(r.info.xlinks_missing, 0u);
    // Footprints in the working frame: explicit geometry for every mesh.
    WorkingFrame frame(r.info.srs_name, {}, c.file);
    std::size_t ok = 0;
    for (Mesh& m : r.meshes) {
      EXPECT_EQ(m.source_file, shared_data(c.file));
      EXPECT_FALSE(m.source_id.empty());
      ASSERT_TRUE(frame.transform(m));
      FootprintResult fp = make_footprint(m);
      if (fp.ok) ++ok;
      else ADD_FAILURE() << m.source_id << ": " << fp.code << " " << fp.reason;
    }
    EXPECT_EQ(ok, c.footprints);
    total_meshes += r.meshes.size();
    total_footprints += ok;
  }
  EXPECT_EQ(total_meshes, expected_meshes);
  EXPECT_EQ(total_footprints, expected_meshes);
}

TEST(CityGmlSamples, EveryFileReadsWithTheStatedCounts) { expect_stated_counts(kSamples, 1577u); }

TEST(CityGmlSamplesThirdParty, EveryFileReadsWithTheStatedCounts) {
  GROUNDPLAN_SKIP_IF_MISSING(shared_data(kThirdPartySamples[0].file));
  expect_stated_counts(kThirdPartySamples, 1776u - 1577u);
}

TEST(CityGmlSamplesThirdParty, BerlinHas83GroundSurfacesIn61Buildings) {
  GROUNDPLAN_SKIP_IF_MISSING(shared_data("citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml"));
  ReadResult r = read_file(shared_data("citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml"));
  EXPECT_EQ(r.info.citygml_version, "1.0");
  EXPECT_EQ(r.info.srs_name, "EPSG:25833");
  std::size_t ground = 0, roof = 0, wall = 0, multi_ground = 0;
  for (const Mesh& m : r.meshes) {
    std::size_t g = faces_of_kind(m, SurfaceKind::Ground);
    ground += g;
    multi_ground += g > 1;
    roof += faces_of_kind(m, SurfaceKind::Roof);
    wall += faces_of_kind(m, SurfaceKind::Wall);
  }
  EXPECT_EQ(ground, 83u);
  EXPECT_GT(multi_ground, 0u);  // several ground polygons per building are normal
  EXPECT_GE(roof, 249u);
  EXPECT_GE(wall, 793u);
  for (const Mesh& m : r.meshes)
    for (const Point3& p : m.vertices) {
      ASSERT_GE(p.x, 390478 - 1);
      ASSERT_LE(p.x, 390703 + 1);
      ASSERT_GE(p.y, 5819214 - 1);
      ASSERT_LE(p.y, 5819553 + 1);
      ASSERT_GE(p.z, 27.5 - 0.1);
      ASSERT_LE(p.z, 64.2 + 0.1);
    }
}

TEST(CityGmlSamples, NiedersachsenBuildingsWithPartsYieldTheirOwnMeshToo) {
  std::size_t buildings = 0, parts = 0, with_parts = 0;
  for (const char* f : {"LoD1_24065860_2_2021-01-25.gml", "LoD1_24065862_2_2021-01-25.gml",
                        "LoD1_24085860_2_2021-01-25.gml", "LoD1_24085862_2_2021-01-25.gml"}) {
    ReadResult r = read_file(shared_data(std::string("citygml1-niedersachsen-lod1-4tiles/") + f));
    std::map<std::string, int> children;
    for (const Mesh& m : r.meshes) {
      if (m.parent_id.empty()) ++buildings;
      else ++parts, ++children[m.parent_id];
      for (const MeshFace& face : m.faces) EXPECT_EQ(face.lod, 1);
    }
    for (const auto& [parent, n] : children) {
      EXPECT_NE(r.find(parent), nullptr) << parent;  // the parent has geometry of its own
      ++with_parts;
    }
  }
  EXPECT_EQ(buildings, 408u);
  EXPECT_EQ(parts, 259u);
  EXPECT_EQ(with_parts, 131u);
}

TEST(CityGmlSamplesThirdParty, DenHaagBuildingWithoutGeometryIsCarriedByItsParts) {
  GROUNDPLAN_SKIP_IF_MISSING(shared_data("citygml-fzkhaus-denhaag-misc/DenHaag_1BwBP.gml"));
  ReadResult r = read_file(shared_data("citygml-fzkhaus-denhaag-misc/DenHaag_1BwBP.gml"));
  ASSERT_EQ(r.meshes.size(), 6u);
  for (const Mesh& m : r.meshes) {
    EXPECT_FALSE(m.parent_id.empty());
    EXPECT_EQ(faces_of_kind(m, SurfaceKind::Ground), 1u);
  }
  EXPECT_EQ(r.info.srs_dimension, 0);  // no srsDimension anywhere: inferred
}

TEST(CityGmlSamplesThirdParty, XlinkedSolidsDoNotDoubleTheFaces) {
  GROUNDPLAN_SKIP_IF_MISSING(shared_data("citygml-citygml4j-samples/lod2_buildings_v3.gml"));
  // 100 houses, each 7 polygons in thematic surfaces + a lod2Solid of 7 xlinks to them.
  ReadResult r = read_file(shared_data("citygml-citygml4j-samples/lod2_buildings_v3.gml"));
  EXPECT_EQ(r.info.xlinks_resolved, 700u);
  for (const Mesh& m : r.meshes) {
    EXPECT_EQ(m.faces.size(), 7u);
    EXPECT_EQ(faces_of_kind(m, SurfaceKind::Ground), 1u);
  }
}

TEST(CityGmlSamples, AttributesAndLodChoice) {
  ReadResult r = read_file(shared_data("citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml"));
  ASSERT_FALSE(r.meshes.empty());
  std::size_t with_height = 0;
  for (const Mesh& m : r.meshes) {
    with_height += m.measured_height > 0;
    for (const MeshFace& f : m.faces) EXPECT_EQ(f.lod, 1);  // lod1Solid beats lod0FootPrint by default
  }
  EXPECT_GT(with_height, 600u);
  CityGmlOptions lod0;
  lod0.lod = 0;
  ReadResult r0 = read_file(shared_data("citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml"), lod0);
  ASSERT_EQ(r0.meshes.size(), 657u);
  for (const Mesh& m : r0.meshes) EXPECT_EQ(faces_of_kind(m, SurfaceKind::FootPrint), m.faces.size());
  CityGmlOptions lod2;
  lod2.lod = 2;
  ReadResult r2 = read_file(shared_data("citygml2-plateau-japan-lod1/53392547_bldg_6697_op2.gml"), lod2);
  EXPECT_EQ(r2.meshes.size(), 0u);
  EXPECT_EQ(r2.count("NO_GEOMETRY_AT_LOD"), 25u);

  ReadResult fzk = read_file(shared_data("citygml-fzkhaus-denhaag-misc/TUM-Main-Entrance.gml"));
  ASSERT_EQ(fzk.meshes.size(), 1u);
  EXPECT_FALSE(fzk.meshes[0].name.empty() && fzk.meshes[0].source_id.empty());
}

TEST(CityGmlSamplesThirdParty, Lod3InteriorRingsAreKept) {
  GROUNDPLAN_SKIP_IF_MISSING(shared_data("citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD3-KIT-IAI-KHH-B36-V1__v3.gml"));
  ReadResult r = read_file(shared_data("citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD3-KIT-IAI-KHH-B36-V1__v3.gml"));
  ASSERT_EQ(r.meshes.size(), 1u);
  std::size_t holes = 0;
  for (const MeshFace& f : r.meshes[0].faces) holes += f.ring_count - 1;
  EXPECT_EQ(holes, 13u);
}

// ---------------------------------------------------------------------------------------------------
// Inline documents, one feature each.

std::string doc(const std::string& body, const std::string& core = "http://www.opengis.net/citygml/2.0",
                const std::string& bldg = "http://www.opengis.net/citygml/building/2.0",
                const std::string& gml = "http://www.opengis.net/gml") {
  return "<?xml version=\"1.0\"?>\n<core:CityModel xmlns:core=\"" + core + "\" xmlns:bldg=\"" + bldg +
         "\" xmlns:gml=\"" + gml + "\" xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n" + body +
         "\n</core:CityModel>\n";
}

std::string building(const std::string& id, const std::string& inner) {
  return "<core:cityObjectMember><bldg:Building gml:id=\"" + id + "\">" + inner +
         "</bldg:Building></core:cityObjectMember>";
}

std::string ground(const std::string& polygon, int lod = 2) {
  std::string l = "bldg:lod" + std::to_string(lod) + "MultiSurface";
  return "<bldg:boundedBy><bldg:GroundSurface><" + l + "><gml:MultiSurface><gml:surfaceMember>" + polygon +
         "</gml:surfaceMember></gml:MultiSurface></" + l + "></bldg:GroundSurface></bldg:boundedBy>";
}

std::string square_poslist(const std::string& id = "", double x0 = 0, double y0 = 0, double z = 0) {
  std::ostringstream s;
  s << "<gml:Polygon" << (id.empty() ? "" : " gml:id=\"" + id + "\"") << "><gml:exterior><gml:LinearRing><gml:posList>";
  s << x0 << " " << y0 << " " << z << " " << x0 + 10 << " " << y0 << " " << z << " " << x0 + 10 << " " << y0 + 10 << " "
    << z << " " << x0 << " " << y0 + 10 << " " << z << " " << x0 << " " << y0 << " " << z;
  s << "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>";
  return s.str();
}

TEST(CityGmlInline, PosListPosAndCoordinatesGiveTheSameRing) {
  const std::string pos_list = square_poslist();
  const std::string pos =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:pos>0 0 0</gml:pos><gml:pos>10 0 0</gml:pos>"
      "<gml:pos>10 10 0</gml:pos><gml:pos>0 10 0</gml:pos><gml:pos>0 0 0</gml:pos></gml:LinearRing></gml:exterior>"
      "</gml:Polygon>";
  const std::string coords =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:coordinates>0,0,0 10,0,0 10,10,0 0,10,0 0,0,0"
      "</gml:coordinates></gml:LinearRing></gml:exterior></gml:Polygon>";
  const std::string coords_cs =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:coordinates cs=\";\" ts=\"|\" decimal=\",\">0,0;0;0|10;0;0|"
      "10;10;0|0;10,0;0|0;0;0</gml:coordinates></gml:LinearRing></gml:exterior></gml:Polygon>";
  for (const std::string& p : {pos_list, pos, coords, coords_cs}) {
    SCOPED_TRACE(p);
    ReadResult r = read_xml(doc(building("B", ground(p))));
    ASSERT_EQ(r.meshes.size(), 1u);
    ASSERT_TRUE(r.problems.empty()) << r.problems[0].reason;
    const Mesh& m = r.meshes[0];
    ASSERT_EQ(m.faces.size(), 1u);
    EXPECT_EQ(m.faces[0].kind, SurfaceKind::Ground);
    EXPECT_EQ(m.faces[0].lod, 2);
    ASSERT_EQ(m.vertices.size(), 4u);  // closing point dropped
    EXPECT_EQ(m.vertices[2], (Point3{10, 10, 0}));
  }
}

TEST(CityGmlInline, SrsDimensionTwoAndInferredDimension) {
  const std::string two =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"2\">0 0 12 0 12 10 0 10 0 0"
      "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>";
  // No srsDimension anywhere: 12 numbers fit 2D (6 points, closed) and 3D (4 points, not closed).
  const std::string inferred =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 12 0 12 10 0 10 5 5 0 0"
      "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>";
  for (const std::string& p : {two, inferred}) {
    ReadResult r = read_xml(doc(building("B", ground(p))));
    ASSERT_EQ(r.meshes.size(), 1u);
    const Mesh& m = r.meshes[0];
    EXPECT_EQ(m.vertices[1], (Point3{12, 0, 0}));
    EXPECT_EQ(m.vertices[2], (Point3{12, 10, 0}));
  }
}

TEST(CityGmlInline, InteriorRingsAndOrientableSurface) {
  const std::string with_hole =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0 10 0 0 10 10 0 0 10 0 0 0 0</gml:posList>"
      "</gml:LinearRing></gml:exterior><gml:interior><gml:LinearRing><gml:posList>2 2 0 2 4 0 4 4 0 4 2 0 2 2 0"
      "</gml:posList></gml:LinearRing></gml:interior></gml:Polygon>";
  const std::string flipped = "<gml:OrientableSurface orientation=\"-\"><gml:baseSurface>" + square_poslist() +
                              "</gml:baseSurface></gml:OrientableSurface>";
  ReadResult r = read_xml(doc(building("B", ground(with_hole) + ground(flipped))));
  ASSERT_EQ(r.meshes.size(), 1u);
  const Mesh& m = r.meshes[0];
  ASSERT_EQ(m.faces.size(), 2u);
  EXPECT_EQ(m.faces[0].ring_count, 2u);
  EXPECT_EQ(m.faces[1].ring_count, 1u);
  // flipped: first vertex kept, the rest reversed: (0,0) (0,10) (10,10) (10,0)
  const std::uint32_t base = m.ring_offsets[m.faces[1].first_ring];
  EXPECT_EQ(m.vertices[m.indices[base + 1]], (Point3{0, 10, 0}));
  EXPECT_EQ(m.vertices[m.indices[base + 3]], (Point3{10, 0, 0}));
}

TEST(CityGmlInline, XlinksWithinAndAcrossBuildings) {
  const std::string solid_refs = [] {
    return std::string("<bldg:lod2Solid><gml:Solid><gml:exterior><gml:CompositeSurface>"
                       "<gml:surfaceMember xlink:href=\"#own\"/>"
                       "</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod2Solid>");
  }();
  // A: reference to its own polygon defined later (no duplicate). B: backward reference to A's
  // polygon. C: forward reference to D's polygon. E: reference to nothing.
  std::string body =
      building("A", "<bldg:lod2Solid><gml:Solid><gml:exterior><gml:CompositeSurface><gml:surfaceMember "
                    "xlink:href=\"#a1\"/></gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod2Solid>" +
                        ground(square_poslist("a1"))) +
      building("B", "<bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember xlink:href=\"#a1\"/>"
                    "</gml:MultiSurface></bldg:lod2MultiSurface>") +
      building("C", "<bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember><gml:OrientableSurface "
                    "orientation=\"-\"><gml:baseSurface xlink:href=\"#d1\"/></gml:OrientableSurface>"
                    "</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface>") +
      building("D", ground(square_poslist("d1", 100, 0))) +
      building("E", ground(square_poslist("e1", 200, 0)) +
                        "<bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember xlink:href=\"#nowhere\"/>"
                        "</gml:MultiSurface></bldg:lod2MultiSurface>");
  ReadResult r = read_xml(doc(body));
  ASSERT_EQ(r.meshes.size(), 5u);
  ASSERT_NE(r.find("A"), nullptr);
  EXPECT_EQ(r.find("A")->faces.size(), 1u);
  ASSERT_NE(r.find("B"), nullptr);
  ASSERT_EQ(r.find("B")->faces.size(), 1u);
  EXPECT_EQ(r.find("B")->vertices[2], (Point3{10, 10, 0}));
  ASSERT_NE(r.find("C"), nullptr);
  ASSERT_EQ(r.find("C")->faces.size(), 1u);
  EXPECT_EQ(r.find("C")->vertices[1], (Point3{100, 10, 0}));  // flipped copy of d1
  EXPECT_EQ(r.find("C")->faces[0].lod, 2);
  EXPECT_EQ(r.info.xlinks_resolved, 3u);
  EXPECT_EQ(r.info.xlinks_missing, 1u);
  ASSERT_EQ(r.count("XLINK_TARGET_MISSING"), 1u);
  for (const Problem& p : r.problems) {
    EXPECT_EQ(p.source_id, "E");
    EXPECT_NE(p.reason.find("nowhere"), std::string::npos);
    EXPECT_EQ(p.stage, "read");
    EXPECT_EQ(p.file, "inline.gml");
  }
}

TEST(CityGmlInline, PartsGetParentIdAndBuildingWithGeometryYieldsItsOwnMesh) {
  std::string part = "<bldg:consistsOfBuildingPart><bldg:BuildingPart gml:id=\"P1\">" +
                     ground(square_poslist("", 10, 0)) + "</bldg:BuildingPart></bldg:consistsOfBuildingPart>";
  ReadResult both = read_xml(doc(building("B", ground(square_poslist()) + part)));
  ASSERT_EQ(both.meshes.size(), 2u);
  ASSERT_NE(both.find("P1"), nullptr);
  EXPECT_EQ(both.find("P1")->parent_id, "B");
  ASSERT_NE(both.find("B"), nullptr);
  EXPECT_TRUE(both.find("B")->parent_id.empty());
  ReadResult parts_only = read_xml(doc(building("B", part)));
  ASSERT_EQ(parts_only.meshes.size(), 1u);
  EXPECT_TRUE(parts_only.problems.empty());
  ReadResult nothing = read_xml(doc(building("B", "<gml:name>empty</gml:name>")));
  EXPECT_EQ(nothing.meshes.size(), 0u);
  EXPECT_EQ(nothing.count("NO_GEOMETRY"), 1u);
}

TEST(CityGmlInline, CityGml3DefaultNamespaceAndAttributes) {
  const std::string xml =
      "<CityModel xmlns=\"http://www.opengis.net/citygml/3.0\" xmlns:bldg=\"http://www.opengis.net/citygml/building/3.0\""
      " xmlns:con=\"http://www.opengis.net/citygml/construction/3.0\" xmlns:g=\"http://www.opengis.net/gml/3.2\">"
      "<cityObjectMember><bldg:Building g:id=\"B3\"><g:name>Haus 3</g:name>"
      "<boundary><con:GroundSurface><lod2MultiSurface><g:MultiSurface><g:surfaceMember>"
      "<g:Polygon><g:exterior><g:LinearRing><g:posList srsDimension=\"3\">0 0 1 5 0 1 5 5 1 0 0 1</g:posList>"
      "</g:LinearRing></g:exterior></g:Polygon></g:surfaceMember></g:MultiSurface></lod2MultiSurface>"
      "</con:GroundSurface></boundary></bldg:Building></cityObjectMember></CityModel>";
  ReadResult r = read_xml(xml);
  EXPECT_EQ(r.info.citygml_version, "3.0");
  ASSERT_EQ(r.meshes.size(), 1u);
  EXPECT_EQ(r.meshes[0].source_id, "B3");
  EXPECT_EQ(r.meshes[0].name, "Haus 3");
  EXPECT_EQ(faces_of_kind(r.meshes[0], SurfaceKind::Ground), 1u);

  ReadResult h = read_xml(doc(building("H", "<bldg:measuredHeight uom=\"m\">12.5</bldg:measuredHeight>" +
                                                 ground(square_poslist()))));
  ASSERT_EQ(h.meshes.size(), 1u);
  EXPECT_DOUBLE_EQ(h.meshes[0].measured_height, 12.5);
}

// Names are split at their own namespace URI, even where another URI of the document is a prefix of it
// (element_names.cpp remembers the URIs it has seen: GML 3.1's is a prefix of GML 3.2's).
TEST(CityGmlInline, NamespaceUrisThatArePrefixesOfOthersAreToldApart) {
  std::string square = square_poslist();
  for (std::string::size_type k; (k = square.find("gml:")) != std::string::npos;) square.replace(k, 4, "g32:");
  const std::string xml = doc(
      "<gml:boundedBy><gml:Envelope srsName=\"EPSG:25832\"><gml:lowerCorner>0 0 0</gml:lowerCorner>"
      "<gml:upperCorner>10 10 0</gml:upperCorner></gml:Envelope></gml:boundedBy>"
      "<core:cityObjectMember><bldg:Building gml:id=\"B\" xmlns:g32=\"http://www.opengis.net/gml/3.2\">"
      "<bldg:boundedBy><bldg:GroundSurface><bldg:lod2MultiSurface><g32:MultiSurface><g32:surfaceMember>" +
      square +
      "</g32:surfaceMember></g32:MultiSurface></bldg:lod2MultiSurface></bldg:GroundSurface></bldg:boundedBy>"
      "</bldg:Building></core:cityObjectMember>");
  ReadResult r = read_xml(xml);
  EXPECT_TRUE(r.info.has_envelope);
  ASSERT_EQ(r.meshes.size(), 1u);
  EXPECT_TRUE(r.problems.empty()) << r.problems[0].code << ": " << r.problems[0].reason;
  EXPECT_EQ(faces_of_kind(r.meshes[0], SurfaceKind::Ground), 1u);
  EXPECT_EQ(r.meshes[0].vertices.size(), 4u);
}

TEST(CityGmlInline, TinReliefAndOtherFeaturesAreSkipped) {
  std::string tin =
      "<core:cityObjectMember><dem:ReliefFeature xmlns:dem=\"http://www.opengis.net/citygml/relief/2.0\">"
      "<dem:reliefComponent><dem:TINRelief><dem:tin><gml:TriangulatedSurface><gml:trianglePatches><gml:Triangle>"
      "<gml:exterior><gml:LinearRing><gml:posList>0 0 0 1 0 0 1 1 0 0 0 0</gml:posList></gml:LinearRing>"
      "</gml:exterior></gml:Triangle></gml:trianglePatches></gml:TriangulatedSurface></dem:tin></dem:TINRelief>"
      "</dem:reliefComponent></dem:ReliefFeature></core:cityObjectMember>";
  ReadResult r = read_xml(doc(tin + building("B", ground(square_poslist()))));
  ASSERT_EQ(r.meshes.size(), 1u);
  EXPECT_EQ(r.meshes[0].faces.size(), 1u);
  // Triangles inside a building are building geometry.
  std::string tri =
      "<bldg:lod2MultiSurface><gml:TriangulatedSurface><gml:trianglePatches><gml:Triangle><gml:exterior>"
      "<gml:LinearRing><gml:posList>0 0 0 1 0 0 1 1 0 0 0 0</gml:posList></gml:LinearRing></gml:exterior>"
      "</gml:Triangle></gml:trianglePatches></gml:TriangulatedSurface></bldg:lod2MultiSurface>";
  ReadResult t = read_xml(doc(building("T", tri)));
  ASSERT_EQ(t.meshes.size(), 1u);
  EXPECT_EQ(t.meshes[0].vertices.size(), 3u);
}

TEST(CityGmlInline, BadBuildingsBecomeProblemsAndReadingGoesOn) {
  const std::string two_points =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0 1 0 0 0 0 0</gml:posList></gml:LinearRing>"
      "</gml:exterior></gml:Polygon>";
  const std::string nan =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0 1 0 NaN 1 1 0 0 0 0</gml:posList>"
      "</gml:LinearRing></gml:exterior></gml:Polygon>";
  const std::string inf =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0 1 0 1e999 1 1 0 0 0 0</gml:posList>"
      "</gml:LinearRing></gml:exterior></gml:Polygon>";
  const std::string junk =
      "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0 1 zero 0 1 1 0 0 0 0</gml:posList>"
      "</gml:LinearRing></gml:exterior></gml:Polygon>";
  ReadResult r = read_xml(doc(building("few", ground(two_points)) + building("nan", ground(nan)) +
                              building("inf", ground(inf)) + building("junk", ground(junk)) +
                              building("good", ground(square_poslist()))));
  ASSERT_EQ(r.meshes.size(), 1u);
  EXPECT_EQ(r.meshes[0].source_id, "good");
  std::map<std::string, std::string> code_of;
  for (const Problem& p : r.problems)
    if (p.code != "NO_GEOMETRY") code_of[p.source_id] = p.code;
  EXPECT_EQ(code_of["few"], "TOO_FEW_POINTS");
  EXPECT_EQ(code_of["nan"], "NOT_FINITE");
  EXPECT_EQ(code_of["inf"], "NOT_FINITE");
  EXPECT_EQ(code_of["junk"], "BAD_COORDINATES");
  EXPECT_EQ(r.count("NO_GEOMETRY"), 4u);  // each lost its only polygon
}

// ---------------------------------------------------------------------------------------------------
// Hostile and broken input: a clear InputError, quickly, nothing leaked.

// (A hang is ctest's timeout; how fast is a benchmark's business, not a clock here.)
template <class F>
std::string expect_input_error(F&& f) {
  std::string what;
  try {
    f();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    what = e.what();
  }
  return what;
}

TEST(CityGmlHostile, BillionLaughsStopsAtTheFirstEntityDeclaration) {
  std::string xml = "<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [\n<!ENTITY lol \"lol\">\n";
  for (int k = 1; k <= 9; ++k)
    xml += "<!ENTITY lol" + std::to_string(k) + " \"" + [&] {
      std::string s;
      for (int j = 0; j < 10; ++j) s += "&lol" + (k == 1 ? std::string() : std::to_string(k - 1)) + ";";
      return s;
    }() + "\">\n";
  xml += "]>\n" + doc(building("B", "<gml:name>&lol9;</gml:name>" + ground(square_poslist()))).substr(22);
  std::vector<Mesh> meshes;
  std::string what = expect_input_error([&] {
    std::vector<Problem> p;
    SourceInfo info;
    read_citygml_buffer(xml, "lolz.gml", {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, p, info);
  });
  EXPECT_NE(what.find("lolz.gml"), std::string::npos) << what;
  EXPECT_NE(what.find("entit"), std::string::npos) << what;
  EXPECT_TRUE(meshes.empty());
}

TEST(CityGmlHostile, ExternalEntityIsNeverRead) {
  for (const std::string& decl : {std::string("<!ENTITY xxe SYSTEM \"file:///etc/passwd\">"),
                                  std::string("<!ENTITY % pe SYSTEM \"file:///etc/passwd\"> %pe;")}) {
    std::string xml = "<?xml version=\"1.0\"?>\n<!DOCTYPE m [ " + decl + " ]>\n" +
                      doc(building("B", "<gml:name>&xxe;</gml:name>" + ground(square_poslist()))).substr(22);
    std::vector<Mesh> meshes;
    std::vector<Problem> problems;
    std::string what = expect_input_error([&] {
      SourceInfo info;
      read_citygml_buffer(xml, "xxe.gml", {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
    });
    EXPECT_EQ(what.find("root:"), std::string::npos) << what;
    for (const Mesh& m : meshes) EXPECT_EQ(m.name.find("root:"), std::string::npos);
    for (const Problem& p : problems) EXPECT_EQ(p.reason.find("root:"), std::string::npos);
  }
  // An external DTD is not loaded either (and not needed).
  std::string with_dtd = "<?xml version=\"1.0\"?>\n<!DOCTYPE m SYSTEM \"file:///etc/passwd\">\n" +
                         doc(building("B", ground(square_poslist()))).substr(22);
  ReadResult r = read_xml(with_dtd);
  EXPECT_EQ(r.meshes.size(), 1u);
}

TEST(CityGmlHostile, DeepNestingIsRefused) {
  std::string xml = "<a>";
  for (int k = 0; k < 100000; ++k) xml += "<b>";
  for (int k = 0; k < 100000; ++k) xml += "</b>";
  xml += "</a>";
  std::string what = expect_input_error([&] { read_xml(xml); });
  EXPECT_NE(what.find("nesting"), std::string::npos) << what;
  // ... also inside a building, in a subtree the reader skips
  std::string deep = "<bldg:address>";
  for (int k = 0; k < 5000; ++k) deep += "<x>";
  for (int k = 0; k < 5000; ++k) deep += "</x>";
  deep += "</bldg:address>";
  what = expect_input_error([&] { read_xml(doc(building("B", deep))); });
  EXPECT_NE(what.find("nesting"), std::string::npos) << what;
}

TEST(CityGmlBrokenThirdParty, TruncatedFileIsAnInputErrorNamingTheFileAfterTheBuildingsBeforeIt) {
  const std::string path = shared_data("citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml");
  GROUNDPLAN_SKIP_IF_MISSING(path);
  std::ifstream in(path, std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(all.size(), 900000u);
  std::string half = all.substr(0, all.size() / 2);
  std::vector<Mesh> meshes;
  std::string what = expect_input_error([&] {
    std::vector<Problem> p;
    SourceInfo info;
    read_citygml_buffer(half, "berlin-half.gml", {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, p, info);
  });
  EXPECT_NE(what.find("berlin-half.gml"), std::string::npos) << what;
  EXPECT_NE(what.find("truncated"), std::string::npos) << what;
  EXPECT_GT(meshes.size(), 10u);
  EXPECT_LT(meshes.size(), 61u);
}

TEST(CityGmlBroken, GarbageAndMissingFiles) {
  std::string garbage;
  for (int k = 0; k < 5000; ++k) garbage += static_cast<char>((k * 7919) % 251 + 1);
  std::string what = expect_input_error([&] { read_xml(garbage); });
  EXPECT_NE(what.find("inline.gml"), std::string::npos) << what;
  what = expect_input_error([&] { read_xml(""); });
  EXPECT_NE(what.find("inline.gml"), std::string::npos) << what;
  what = expect_input_error([&] { read_file("/nonexistent/city.gml"); });
  EXPECT_NE(what.find("/nonexistent/city.gml"), std::string::npos) << what;
  // Well-formed XML that is not CityGML: no meshes, one note.
  ReadResult r = read_xml("<kml xmlns=\"http://www.opengis.net/kml/2.2\"><Document/></kml>");
  EXPECT_TRUE(r.meshes.empty());
  EXPECT_EQ(r.count("NOT_CITYGML"), 1u);
}

TEST(CityGmlSniff, LooksLikeCityGml) {
  EXPECT_TRUE(looks_like_citygml(doc("")));
  EXPECT_FALSE(looks_like_citygml("<kml xmlns=\"http://www.opengis.net/kml/2.2\"/>"));
}

}  // namespace
}  // namespace groundplan::gis

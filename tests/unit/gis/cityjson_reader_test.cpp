// SPDX-License-Identifier: MIT
// CityJSON / CityJSONSeq reader (issue 16): real 3DBAG and citygml4j files against their CityJSONSeq
// and CityGML twins, synthetic files for each geometry type, templates, semantics, LoD choice, and
// hostile input (each defect a Problem naming the object; the rest read).
#include <groundplan/error.h>
#include <groundplan/gis/cityjson.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/gis/lod_choice.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/reader.h>

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "test_support.h"

namespace groundplan {
namespace {

/// A temporary file for the length of a test.
struct MemFile {
  std::string path;
  MemFile(const std::string& name, const std::string& text) {
    const auto dir = std::filesystem::temp_directory_path() / ("groundplan_cityjson_test_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    path = (dir / name).string();
    std::ofstream(path, std::ios::binary) << text;
  }
  ~MemFile() { std::filesystem::remove(path); }
};

struct Read {
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  gis::ReadInfo info;
  const Mesh* mesh(const std::string& id) const {
    for (const Mesh& m : meshes)
      if (m.source_id == id) return &m;
    return nullptr;
  }
  std::size_t count(const std::string& code) const {
    return static_cast<std::size_t>(
        std::count_if(problems.begin(), problems.end(), [&](const Problem& p) { return p.code == code; }));
  }
};

Read read(const std::string& path, const gis::ReadOptions& options = {}) {
  Read r;
  gis::read_any(path, options, [&](Mesh&& m) { r.meshes.push_back(std::move(m)); }, r.problems, r.info);
  return r;
}

std::size_t faces_of(const Mesh& m, SurfaceKind k) {
  return static_cast<std::size_t>(std::count_if(m.faces.begin(), m.faces.end(), [&](const MeshFace& f) { return f.kind == k; }));
}

// A unit cube's six faces on vertices 0..7 as a Solid shell (outward), ground first.
const char* kCubeShell = R"([[[0,3,2,1]],[[4,5,6,7]],[[0,1,5,4]],[[1,2,6,5]],[[2,3,7,6]],[[3,0,4,7]]])";
const char* kCubeVertices = R"([[0,0,0],[1000,0,0],[1000,1000,0],[0,1000,0],[0,0,1000],[1000,0,1000],[1000,1000,1000],[0,1000,1000]])";
const char* kCubeSemantics = R"({"surfaces":[{"type":"GroundSurface"},{"type":"RoofSurface"},{"type":"WallSurface"}],"values":[[0,1,2,2,2,2]]})";

std::string cube_file(const std::string& objects, const std::string& extra_vertices = "") {
  std::string v = kCubeVertices;
  if (!extra_vertices.empty()) v = v.substr(0, v.size() - 1) + "," + extra_vertices + "]";
  return std::string(R"({"type":"CityJSON","version":"2.0","CityObjects":)") + objects + R"(,"vertices":)" + v +
         R"(,"transform":{"scale":[0.001,0.001,0.001],"translate":[100000,400000,0]},)"
         R"("metadata":{"referenceSystem":"https://www.opengis.net/def/crs/EPSG/0/7415"}})";
}

TEST(CityJsonReader, SolidWithTransformSemanticsAndParts) {
  const std::string objects = std::string(R"({"B1":{"type":"Building","children":["B1-0"]},)") +
                              R"("B1-0":{"type":"BuildingPart","parents":["B1"],"attributes":{"measuredHeight":12.5},)" +
                              R"("geometry":[{"type":"Solid","lod":"2.2",)" +
                              R"("boundaries":[)" + kCubeShell + R"(],"semantics":)" + kCubeSemantics + "}]}," +
                              // read after the part: nothing of the part's (parent, height) carries over
                              R"("B2":{"type":"Building","geometry":[{"type":"Solid","lod":"2.2","boundaries":[)" +
                              kCubeShell + "]}]}}";
  MemFile f("solid.city.json", cube_file(objects));
  const Read r = read(f.path);
  EXPECT_EQ(r.info.format, gis::InputFormat::CityJson);
  ASSERT_EQ(r.meshes.size(), 2u);  // B1 has no geometry of its own: its part carries it; and B2
  const Mesh& m = r.meshes[0];
  EXPECT_EQ(m.measured_height, 12.5);
  ASSERT_EQ(r.meshes[1].source_id, "B2");
  EXPECT_EQ(r.meshes[1].parent_id, "");
  EXPECT_LT(r.meshes[1].measured_height, 0);
  EXPECT_EQ(m.source_id, "B1-0");
  EXPECT_EQ(m.parent_id, "B1");
  EXPECT_EQ(m.faces.size(), 6u);
  EXPECT_EQ(faces_of(m, SurfaceKind::Ground), 1u);
  EXPECT_EQ(faces_of(m, SurfaceKind::Roof), 1u);
  EXPECT_EQ(faces_of(m, SurfaceKind::Wall), 4u);
  EXPECT_EQ(m.faces[0].lod, 2);
  // transform: integer * 0.001 + translate
  EXPECT_DOUBLE_EQ(m.vertices[m.indices[m.ring_offsets[0] + 1]].x, 100000.0);
  EXPECT_DOUBLE_EQ(m.vertices[m.indices[m.ring_offsets[0] + 1]].y, 400001.0);
  EXPECT_EQ(r.info.citygml.srs_name, "https://www.opengis.net/def/crs/EPSG/0/7415");
  EXPECT_TRUE(r.problems.empty());
}

TEST(CityJsonReader, CityJson10NumericLodNoTransformMultiSurfaceAndUrn) {
  const std::string doc = R"({"type":"CityJSON","version":"1.0","metadata":{"referenceSystem":"urn:ogc:def:crs:EPSG::28992"},
    "CityObjects":{"A":{"type":"Building","geometry":[
      {"type":"MultiSurface","lod":1,"boundaries":[[[0,1,2,3]]]},
      {"type":"CompositeSurface","lod":2,"boundaries":[[[0,1,2,3]],[[4,5,6,7]]],
       "semantics":{"surfaces":[{"type":"GroundSurface"}],"values":[0,null]}}]}},
    "vertices":[[0.5,0,0],[10,0,0],[10,10,0],[0,10,0],[0,0,5],[10,0,5],[10,10,5],[0,10,5]]})";
  MemFile f("old.json", doc);  // plain .json: found by content
  const Read r = read(f.path);
  EXPECT_EQ(r.info.format, gis::InputFormat::CityJson);
  ASSERT_EQ(r.meshes.size(), 1u);
  EXPECT_EQ(r.meshes[0].faces.size(), 2u);  // the highest LoD (2) only
  EXPECT_EQ(faces_of(r.meshes[0], SurfaceKind::Ground), 1u);
  EXPECT_EQ(faces_of(r.meshes[0], SurfaceKind::Unknown), 1u);
  EXPECT_DOUBLE_EQ(r.meshes[0].vertices[0].x, 0.5);
  EXPECT_EQ(r.info.cityjson.version, "1.0");

  gis::ReadOptions lod1;
  lod1.lod = 1;
  const Read r1 = read(f.path, lod1);
  ASSERT_EQ(r1.meshes.size(), 1u);
  EXPECT_EQ(r1.meshes[0].faces.size(), 1u);
  EXPECT_EQ(r1.meshes[0].faces[0].lod, 1);
}

TEST(CityJsonReader, LodRefinementsAs3dbagNamesThem) {
  // One Solid per LoD "1.2", "1.3", "2.2": each a box of a different height, so the LoD read shows.
  // vertices 4..7 are the top at 1 m; shell(4) uses 8..11 (2 m), shell(8) 12..15 (3 m)
  auto shell = [](int t) {
    const int a = 4 + t, b = 5 + t, c = 6 + t, d = 7 + t;
    auto n = [](int i) { return std::to_string(i); };
    return "[[[0,3,2,1]],[[" + n(a) + "," + n(b) + "," + n(c) + "," + n(d) + "]],[[0,1," + n(b) + "," + n(a) + "]],[[1,2," +
           n(c) + "," + n(b) + "]],[[2,3," + n(d) + "," + n(c) + "]],[[3,0," + n(a) + "," + n(d) + "]]]";
  };
  const std::string objects = R"({"P":{"type":"Building","geometry":[)"
                              R"({"type":"Solid","lod":"1.2","boundaries":[)" + shell(0) + R"(]},)"
                              R"({"type":"Solid","lod":"2.2","boundaries":[)" + shell(4) + R"(]},)"
                              R"({"type":"Solid","lod":"1.3","boundaries":[)" + shell(8) + R"(]}]}})";
  const std::string extra = "[0,0,2000],[1000,0,2000],[1000,1000,2000],[0,1000,2000],"
                            "[0,0,3000],[1000,0,3000],[1000,1000,3000],[0,1000,3000]";
  MemFile f("lods.city.json", cube_file(objects, extra));
  auto top_z = [&](int lod, int refinement) {
    gis::ReadOptions o;
    o.lod = lod;
    o.lod_refinement = refinement;
    const Read r = read(f.path, o);
    EXPECT_EQ(r.meshes.size(), 1u);
    if (r.meshes.empty()) return -1.0;
    double z = 0;
    for (const Point3& p : r.meshes[0].vertices) z = std::max(z, p.z);
    return z;
  };
  EXPECT_DOUBLE_EQ(top_z(-1, -1), 2.0);  // 2.2, the highest
  EXPECT_DOUBLE_EQ(top_z(1, -1), 3.0);   // 1.3, the highest of LoD 1
  EXPECT_DOUBLE_EQ(top_z(1, 2), 1.0);    // 1.2 as asked
  EXPECT_DOUBLE_EQ(top_z(2, 2), 2.0);
  gis::ReadOptions o;
  o.lod = 1;
  o.lod_refinement = 1;
  const Read none = read(f.path, o);
  EXPECT_TRUE(none.meshes.empty());
  ASSERT_EQ(none.count("NO_GEOMETRY_AT_LOD"), 1u);
  EXPECT_NE(none.problems[0].reason.find("1.2, 2.2, 1.3"), std::string::npos) << none.problems[0].reason;

  EXPECT_EQ(gis::parse_lod_choice("2.2", "--lod ").refinement, 2);
  EXPECT_EQ(gis::parse_lod_choice("-1", "--lod ").lod, -1);
  EXPECT_EQ(gis::parse_lod_choice("3", "--lod ").lod, 3);
  EXPECT_THROW(gis::parse_lod_choice("5", "--lod "), InvalidArgument);
  EXPECT_THROW(gis::parse_lod_choice("2.22", "--lod "), InvalidArgument);
  EXPECT_THROW(gis::parse_lod_choice("", "--lod "), InvalidArgument);
}

TEST(CityJsonReader, MultiSolidAndGeometryInstance) {
  // A template: the unit square ground + roof, 1 m x 1 m, placed twice with a scale of 2.
  const std::string doc = R"({"type":"CityJSON","version":"1.1",
    "geometry-templates":{"templates":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,3,2,1]],[[4,5,6,7]]],
        "semantics":{"surfaces":[{"type":"GroundSurface"},{"type":"RoofSurface"}],"values":[0,1]}}],
      "vertices-templates":[[0,0,0],[1,0,0],[1,1,0],[0,1,0],[0,0,1],[1,0,1],[1,1,1],[0,1,1]]},
    "CityObjects":{
      "I":{"type":"Building","geometry":[{"type":"GeometryInstance","template":0,"boundaries":[0],
        "transformationMatrix":[2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,0,1]}]},
      "S":{"type":"Building","geometry":[{"type":"MultiSolid","lod":"1","boundaries":[[)" +
                          std::string(kCubeShell) + "],[" + kCubeShell + R"(]]}]}},
    "vertices":[[10,20,0],[11,20,0],[11,21,0],[10,21,0],[10,20,1],[11,20,1],[11,21,1],[10,21,1]]})";
  MemFile f("inst.city.json", doc);
  const Read r = read(f.path);
  ASSERT_EQ(r.meshes.size(), 2u) << (r.problems.empty() ? "" : r.problems[0].reason);
  const Mesh* inst = r.mesh("I");
  ASSERT_TRUE(inst);
  ASSERT_EQ(inst->faces.size(), 2u);
  EXPECT_EQ(faces_of(*inst, SurfaceKind::Ground), 1u);
  double maxx = 0, maxz = 0;
  for (const Point3& p : inst->vertices) maxx = std::max(maxx, p.x), maxz = std::max(maxz, p.z);
  EXPECT_DOUBLE_EQ(maxx, 12.0);  // 10 + 2 * 1
  EXPECT_DOUBLE_EQ(maxz, 2.0);
  ASSERT_TRUE(r.mesh("S"));
  EXPECT_EQ(r.mesh("S")->faces.size(), 12u);
  EXPECT_TRUE(r.problems.empty());
}

TEST(CityJsonReader, HostileObjectsAreProblemsAndTheRestIsRead) {
  const std::string good = R"("ok":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":[)" +
                           std::string(kCubeShell) + "]}]}";
  const std::string objects = "{" + good + R"(,
    "idx":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,99999999]],[[0,1,2]]]}]},
    "hole":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,2,3],[4,5]]]}]},
    "neg":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,-2]]]}]},
    "huge":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,8]]]}]},
    "shape":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":"not an array"}]},
    "tpl":{"type":"Building","geometry":[{"type":"GeometryInstance","template":7,"boundaries":[0],"transformationMatrix":[]}]},
    "lines":{"type":"Building","geometry":[{"type":"MultiLineString","lod":"1","boundaries":[[0,1]]}]},
    "nolod":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"9.9.9","boundaries":[[[0,1,2]]]}]},
    "deep":{"type":"Building","attributes":{"a":)" + std::string(200, '[') + std::string(200, ']') + R"(}},
    "notype":{"geometry":[]}})";
  MemFile f("bad.city.json", cube_file(objects, "[1e999,0,0]"));
  const Read r = read(f.path);
  ASSERT_EQ(r.meshes.size(), 3u);  // "ok", "idx" keeps its good surface, "hole" its outer ring
  EXPECT_TRUE(r.mesh("ok"));
  ASSERT_TRUE(r.mesh("idx"));
  EXPECT_EQ(r.mesh("idx")->faces.size(), 1u);
  // Nothing of a dropped surface or ring stays in the mesh (the reader writes rings straight into it).
  EXPECT_EQ(r.mesh("idx")->vertices.size(), 3u);
  EXPECT_EQ(r.mesh("idx")->ring_offsets.size(), 2u);
  ASSERT_TRUE(r.mesh("hole"));
  ASSERT_EQ(r.mesh("hole")->faces.size(), 1u);
  EXPECT_EQ(r.mesh("hole")->faces[0].ring_count, 1u);
  EXPECT_EQ(r.mesh("hole")->vertices.size(), 4u);
  EXPECT_EQ(r.mesh("hole")->indices.size(), 4u);
  std::map<std::string, std::string> code_of;
  for (const Problem& p : r.problems) code_of[p.source_id] += p.code + " ";
  EXPECT_EQ(code_of["idx"], "BAD_VERTEX_INDEX ");
  EXPECT_EQ(code_of["hole"], "TOO_FEW_POINTS ");
  EXPECT_EQ(code_of["neg"], "BAD_VERTEX_INDEX NO_GEOMETRY ");
  EXPECT_EQ(code_of["huge"], "NOT_FINITE NO_GEOMETRY ");
  EXPECT_EQ(code_of["shape"], "BAD_GEOMETRY NO_GEOMETRY ");
  EXPECT_EQ(code_of["tpl"], "BAD_TEMPLATE NO_GEOMETRY ");
  EXPECT_EQ(code_of["lines"], "NO_GEOMETRY ");
  EXPECT_EQ(code_of["nolod"], "BAD_LOD NO_GEOMETRY ");
  EXPECT_EQ(code_of["deep"], "BAD_CITYOBJECT ");  // nesting past max_depth
  EXPECT_EQ(code_of["notype"], "BAD_CITYOBJECT ");
  EXPECT_EQ(code_of[""], "NOT_FINITE ");  // the 1e999 vertex, once for the file
  for (const Problem& p : r.problems) EXPECT_EQ(p.file, f.path);
}

// A valid file is read as one DOM (the fast path); one broken object sends the file to the
// object-by-object path. Both give the same meshes for the same objects, vertex for vertex.
TEST(CityJsonReader, WholeFileAndObjectByObjectPathsAgree) {
  std::string objects = "{";
  for (int i = 0; i < 3; ++i)
    objects += std::string(i ? "," : "") + "\"b" + std::to_string(i) +
               R"(":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":[)" + kCubeShell +
               R"(],"semantics":)" + kCubeSemantics + "}]}";
  MemFile fast("fast.city.json", cube_file(objects + "}", "[5000,5000,0]"));
  MemFile slow("slow.city.json", cube_file(objects + R"(,"broken":{"type":"Building","attributes":{"a":)" +
                                               std::string(200, '[') + std::string(200, ']') + "}}}",
                                           "[5000,5000,0]"));
  for (int pass = 0; pass < 2; ++pass) {  // the second time with the thread's buffers reused
    const Read a = read(fast.path), b = read(slow.path);
    EXPECT_TRUE(a.problems.empty());
    ASSERT_EQ(b.problems.size(), 1u);
    EXPECT_EQ(b.problems[0].source_id, "broken");
    EXPECT_EQ(a.info.cityjson.vertices, 9u);
    EXPECT_EQ(b.info.cityjson.vertices, 9u);
    EXPECT_EQ(a.info.citygml.srs_name, b.info.citygml.srs_name);
    ASSERT_EQ(a.meshes.size(), 3u);
    ASSERT_EQ(b.meshes.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(a.meshes[i].source_id, b.meshes[i].source_id);
      ASSERT_EQ(a.meshes[i].vertices.size(), b.meshes[i].vertices.size());
      for (std::size_t k = 0; k < a.meshes[i].vertices.size(); ++k) {
        EXPECT_EQ(a.meshes[i].vertices[k].x, b.meshes[i].vertices[k].x);
        EXPECT_EQ(a.meshes[i].vertices[k].y, b.meshes[i].vertices[k].y);
        EXPECT_EQ(a.meshes[i].vertices[k].z, b.meshes[i].vertices[k].z);
      }
      EXPECT_EQ(faces_of(a.meshes[i], SurfaceKind::Ground), faces_of(b.meshes[i], SurfaceKind::Ground));
    }
    EXPECT_DOUBLE_EQ(a.meshes[0].vertices[0].x, 100000.0);  // transform applied: 0 * 0.001 + 100000
  }
}

TEST(CityJsonReader, BrokenFilesThrowInputErrorNamingTheFile) {
  const std::string good = cube_file(R"({"ok":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":[)" +
                                     std::string(kCubeShell) + "]}]}}");
  for (const std::string& text : {good.substr(0, good.size() / 2), std::string("{\"type\":\"CityJSON\"}"),
                                  std::string("{\"type\":\"CityJSONFeature\",\"CityObjects\":{}}"),
                                  std::string(100000, '[') + std::string(100000, ']'), std::string("")}) {
    MemFile f("broken.city.json", text);
    try {
      read(f.path);
      ADD_FAILURE() << "no error for " << text.substr(0, 60);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(f.path), std::string::npos) << e.what();
    }
  }
}

TEST(CityJsonReader, SequenceBadLinesAreProblemsAndLongLinesSkipped) {
  const std::string header =
      R"({"type":"CityJSON","version":"2.0","transform":{"scale":[0.001,0.001,0.001],"translate":[0,0,0]},"CityObjects":{},"vertices":[],)"
      R"("metadata":{"referenceSystem":"https://www.opengis.net/def/crs/EPSG/0/28992"}})";
  auto feature = [](const std::string& id) {
    return R"({"type":"CityJSONFeature","id":")" + id + R"(","CityObjects":{")" + id +
           R"(":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":[)" + kCubeShell +
           R"(]}]}},"vertices":)" + kCubeVertices + "}";
  };
  const std::string text = header + "\n" + feature("a") + "\n{not json\n\n" + feature("b") + "\r\n" +
                           R"({"type":"CityJSONFeature","id":"c","CityObjects":{}})" + "\n" + feature("d");  // no final newline
  MemFile f("seq.city.jsonl", text);
  const Read r = read(f.path);
  EXPECT_EQ(r.info.format, gis::InputFormat::CityJsonSeq);
  ASSERT_EQ(r.meshes.size(), 3u);
  EXPECT_TRUE(r.mesh("a") && r.mesh("b") && r.mesh("d"));
  EXPECT_EQ(r.count("BAD_LINE"), 2u);  // line 3 (not JSON), line 6 (no vertices)
  EXPECT_EQ(r.info.citygml.srs_name, "https://www.opengis.net/def/crs/EPSG/0/28992");

  gis::ReadOptions small;
  small.cityjson.max_line_bytes = header.size() + 10;  // features are longer
  const Read s = read(f.path, small);
  EXPECT_TRUE(s.meshes.empty());
  EXPECT_EQ(s.count("LINE_TOO_LONG"), 3u);

  MemFile no_header("nohead.city.jsonl", feature("a") + "\n");
  EXPECT_THROW(read(no_header.path), InputError);
}

// A feature's members are found as a lookup by key finds them (the first of a repeated key), each
// vertex needs exactly three numbers, and a line longer than the 1 MiB read chunk is read whole.
TEST(CityJsonReader, SequenceFeatureMembersVerticesAndLinesAcrossChunks) {
  const std::string header =
      R"({"type":"CityJSON","version":"2.0","transform":{"scale":[0.001,0.001,0.001],"translate":[0,0,0]},"CityObjects":{},"vertices":[]})";
  auto feature = [](const std::string& id, const std::string& before, const std::string& vertices,
                    const std::string& after) {
    return R"({"type":"CityJSONFeature")" + before + R"(,"id":")" + id + R"(","CityObjects":{")" + id +
           R"(":{"type":"Building","geometry":[{"type":"Solid","lod":"2","boundaries":[)" + kCubeShell +
           R"(]}]}},"vertices":)" + vertices + after + "}";
  };
  std::string two_numbers = kCubeVertices;  // vertex 7 loses its z
  two_numbers.replace(two_numbers.rfind(",1000]"), 6, "]");
  const std::string big(1536 * 1024, 'x');  // the line spans two read chunks
  const std::string text = header + "\n" + feature("a", "", kCubeVertices, R"(,"vertices":[])") + "\n" +
                           feature("b", "", two_numbers, "") + "\n" +
                           feature("c", R"(,"type":"Other")", kCubeVertices, "") + "\n" +
                           feature("d", R"(,"attributes":{"note":")" + big + "\"}", kCubeVertices, "") + "\n" +
                           feature("e", "", kCubeVertices, "") + "\n";
  MemFile f("members.city.jsonl", text);
  const Read r = read(f.path);
  EXPECT_EQ(r.count("BAD_LINE"), 0u);
  // Line 3's vertex 7 has two numbers: said once by the reader (then again for each surface on it).
  const auto said = std::count_if(r.problems.begin(), r.problems.end(), [](const Problem& p) {
    return p.code == "NOT_FINITE" && p.reason.find("line 3 \"vertices\": 1 vertices") != std::string::npos;
  });
  EXPECT_EQ(said, 1);
  for (const char* id : {"a", "c", "d", "e"}) {
    const Mesh* m = r.mesh(id);
    ASSERT_TRUE(m) << id;
    EXPECT_EQ(m->faces.size(), 6u) << id;
  }
  const Mesh* b = r.mesh("b");
  EXPECT_TRUE(b == nullptr || b->faces.size() < 6u);  // faces on vertex 7 dropped
  EXPECT_EQ(r.info.cityjson.features, 5u);
}

TEST(CityJsonReader, DetectionAndFolderNames) {
  EXPECT_EQ(gis::detect_format("x.city.json", ""), gis::InputFormat::CityJson);
  EXPECT_EQ(gis::detect_format("x.city.jsonl", ""), gis::InputFormat::CityJsonSeq);
  EXPECT_EQ(gis::detect_format("x.json", R"({"type": "CityJSON", "version": "2.0"})"), gis::InputFormat::CityJson);
  EXPECT_EQ(gis::detect_format("x.json", "{\n  \"version\": \"1.1\",\n  \"type\": \"CityJSON\"\n}"), gis::InputFormat::CityJson);
  EXPECT_EQ(gis::detect_format("x.json", "{\"type\":\"CityJSON\"}\n{\"type\":\"CityJSONFeature\"}"),
            gis::InputFormat::CityJsonSeq);
  EXPECT_EQ(gis::detect_format("tileset.json", R"({"asset":{"version":"1.0"},"root":{}})"), gis::InputFormat::Gltf);
  EXPECT_EQ(gis::detect_format("x.json", R"({"type":"FeatureCollection"})"), gis::InputFormat::Unknown);
  EXPECT_TRUE(gis::is_input_name("a.city.json"));
  EXPECT_TRUE(gis::is_input_name("A.CITY.JSONL"));
  EXPECT_FALSE(gis::is_input_name("tileset.json"));
}

// --- real data ------------------------------------------------------------------------------------


double plan_area(const gis::PipelineResult& r) {
  double a = 0;
  for (const GroundPlan& p : r.plans) a += p.area_m2;
  return a;
}

TEST(CityJsonReal, ThreeDBagFileAndSequenceGiveTheSamePlans) {
  gis::PipelineOptions o;
  o.inputs = {test::shared_data("cityjson-3dbag-cjseq/3dbag_b2.city.json")};
  const gis::PipelineResult whole = gis::run_pipeline(o);
  o.inputs = {test::shared_data("cityjson-3dbag-cjseq/3dbag_b2.city.jsonl")};
  const gis::PipelineResult seq = gis::run_pipeline(o);
  EXPECT_EQ(whole.buildings_read, 2u);  // the two BuildingParts; their Buildings have no geometry of their own
  EXPECT_EQ(whole.footprints.size(), 2u);
  EXPECT_EQ(whole.crs_name, "EPSG:28992");  // EPSG:7415 = RD New + NAP
  ASSERT_FALSE(whole.plans.empty());
  EXPECT_EQ(test::plan_keys(whole.plans), test::plan_keys(seq.plans));
  EXPECT_EQ(seq.footprints.size(), 2u);
  for (const Footprint& fp : whole.footprints) {
    EXPECT_EQ(fp.method, "ground-surface") << fp.source_id;
    EXPECT_EQ(fp.source_id.rfind("NL.IMBAG.Pand.", 0), 0u);
  }
  const gis::GeosComparison cmp = gis::compare_with_geos(whole.footprints, whole.plans);
  EXPECT_TRUE(cmp.matches(1e-9)) << cmp.summary();

  // Decomposition of the walls and roofs agrees with the GroundSurfaces.
  o.footprints = gis::FootprintMode::Decompose;
  const gis::PipelineResult dec = gis::run_pipeline(o);
  ASSERT_EQ(dec.footprints.size(), 2u);
  EXPECT_NEAR(plan_area(dec), plan_area(whole), 1e-3 * plan_area(whole));
}

TEST(CityJsonRealThirdParty, Citygml4jCityJsonGivesTheSamePlansAsItsCityGml) {
  GROUNDPLAN_SKIP_IF_MISSING(test::shared_data("citygml-citygml4j-samples/lod2_buildings_v2.json"));
  gis::PipelineOptions o;
  o.inputs = {test::shared_data("citygml-citygml4j-samples/lod2_buildings_v2.json")};
  const gis::PipelineResult json = gis::run_pipeline(o);
  o.inputs = {test::shared_data("citygml-citygml4j-samples/lod2_buildings_v3.gml")};
  const gis::PipelineResult gml = gis::run_pipeline(o);
  EXPECT_EQ(json.buildings_read, 100u);
  EXPECT_EQ(json.footprints.size(), gml.footprints.size());
  EXPECT_EQ(json.crs_name, gml.crs_name);
  ASSERT_FALSE(json.plans.empty());
  EXPECT_EQ(test::plan_keys(json.plans), test::plan_keys(gml.plans));
}

}  // namespace
}  // namespace groundplan

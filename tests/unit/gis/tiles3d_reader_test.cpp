// SPDX-License-Identifier: MIT
// 3D Tiles and compressed glTF: the tilesets of tests/data/3dtiles (made from a CityGML sample by
// make_tilesets.py with ElementTree, earcut, pyproj, and CesiumGS's 3d-tiles-tools, gltf-pipeline and
// gltfpack: see SOURCE.txt there) give the plans of that CityGML, one building per feature; levels of
// detail; the georeference against pyproj's; hostile tilesets and tiles as problems.
#include <groundplan/error.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/reader.h>

#include <geos_c.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "read_all.h"
#include "test_config.h"
#include "test_support.h"

#include <cpl_conv.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace groundplan {
namespace {

const std::string kCityGml = "citygml1-niedersachsen-lod1-4tiles/LoD1_24065862_2_2021-01-25.gml";
constexpr std::size_t kBuildings = 80;  // top-level Buildings of kCityGml (make_tilesets.py: 40 west, 40 east)

std::string tiles(const std::string& rel) { return std::string(GROUNDPLAN_TEST_DATA_DIR) + "/data/3dtiles/" + rel; }

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

constexpr double kSnap = 1e-3;

gis::PipelineResult run(const std::string& input, const std::string& id_field = "") {
  gis::PipelineOptions o;
  o.inputs = {input};
  o.t_srs = "EPSG:25832";  // the CityGML's own CRS (ETRS89 / UTM 32N): both read into the same frame
  o.ogr_input.id_field = id_field;
  // Buildings that touch in the CityGML share coordinates exactly; stored as float32 they are ~0.1 mm apart
  // and would not unite. --snap 1 mm (for both inputs alike) makes vertices and edges that close shared.
  o.detail.snap_m = kSnap;
  return gis::run_pipeline(o);
}

/// The plans as one GEOS geometry (a multipolygon of every plan), for distances between two results.
struct Geos {
  GEOSContextHandle_t h = GEOS_init_r();
  ~Geos() { GEOS_finish_r(h); }
  GEOSGeometry* ring(const Ring& r) const {
    GEOSCoordSequence* s = GEOSCoordSeq_create_r(h, static_cast<unsigned>(r.size() + 1), 2);
    for (std::size_t k = 0; k <= r.size(); ++k) {
      const Point2& p = r[k % r.size()];
      GEOSCoordSeq_setXY_r(h, s, static_cast<unsigned>(k), p.x, p.y);
    }
    return GEOSGeom_createLinearRing_r(h, s);
  }
  GEOSGeometry* polygons(const std::vector<Polygon>& polygons) const {
    std::vector<GEOSGeometry*> polys;
    for (const Polygon& p : polygons) {
      std::vector<GEOSGeometry*> holes;
      for (const Ring& r : p.holes) holes.push_back(ring(r));
      polys.push_back(GEOSGeom_createPolygon_r(h, ring(p.outer), holes.data(), static_cast<unsigned>(holes.size())));
    }
    return GEOSGeom_createCollection_r(h, GEOS_MULTIPOLYGON, polys.data(), static_cast<unsigned>(polys.size()));
  }
  GEOSGeometry* plans(const std::vector<GroundPlan>& plans) const {
    std::vector<Polygon> p;
    for (const GroundPlan& g : plans) p.push_back(g.polygon);
    return polygons(p);
  }
  /// The area a footprint's polygons cover (their union: a solid's bottom is many triangles) and its perimeter.
  std::pair<double, double> area_and_perimeter(const std::vector<Polygon>& p) const {
    GEOSGeometry* all = polygons(p);
    GEOSGeometry* u = GEOSUnaryUnion_r(h, all);
    double area = -1, length = -1;
    GEOSArea_r(h, u, &area);
    GEOSLength_r(h, u, &length);
    GEOSGeom_destroy_r(h, u);
    GEOSGeom_destroy_r(h, all);
    return {area, length};
  }
  /// Hausdorff distance (edges densified into 10 pieces) and the area of the symmetric difference.
  std::pair<double, double> distance(const std::vector<GroundPlan>& a, const std::vector<GroundPlan>& b) const {
    GEOSGeometry* ga = plans(a);
    GEOSGeometry* gb = plans(b);
    double d = -1, area = -1;
    GEOSHausdorffDistanceDensify_r(h, ga, gb, 0.1, &d);
    GEOSGeometry* x = GEOSSymDifference_r(h, ga, gb);
    GEOSArea_r(h, x, &area);
    GEOSGeom_destroy_r(h, x);
    GEOSGeom_destroy_r(h, ga);
    GEOSGeom_destroy_r(h, gb);
    return {d, area};
  }
};

std::set<std::string> ids(const gis::PipelineResult& r) {
  std::set<std::string> s;
  for (const Footprint& f : r.footprints) s.insert(f.source_id);
  return s;
}

std::string problems(const gis::PipelineResult& r) {
  std::string s;
  for (const Problem& p : r.problems) s += p.code + " " + p.file + " [" + p.source_id + "]: " + p.reason + "\n";
  return s;
}

const gis::PipelineResult& citygml() {
  static const gis::PipelineResult r = run(test::shared_data(kCityGml));
  return r;
}

/// The CityGML's top-level Building ids: the footprints that are not BuildingParts (parts have ids of their own).
std::set<std::string> building_ids() {
  std::set<std::string> s;
  const std::string text = slurp(test::shared_data(kCityGml));
  for (std::size_t at = text.find("<bldg:Building gml:id=\""); at != std::string::npos;
       at = text.find("<bldg:Building gml:id=\"", at + 1)) {
    const std::size_t from = at + 23;
    s.insert(text.substr(from, text.find('"', from) - from));
  }
  return s;
}

// The tolerance of plans read from tiles against the CityGML's: the tiles store float32 positions
// relative to a centre at most ~1.3 km away (ENU or ECEF offsets), where float32's spacing is 2^-13 m
// (0.12 mm), so each stored coordinate is within 0.06 mm of the double; turned back through the
// transforms (doubles) and PROJ, a vertex lands within ~0.1 mm of the CityGML's. 1 mm leaves room and
// is still far below any real difference (a lost or shifted wall is metres).
constexpr double kFloat32Tolerance = 1e-3;

void expect_plans_of_citygml(const gis::PipelineResult& r, double tolerance, const std::string& what) {
  const gis::PipelineResult& g = citygml();
  ASSERT_FALSE(g.plans.empty());
  EXPECT_EQ(r.crs_name, g.crs_name) << what;
  EXPECT_EQ(r.plans.size(), g.plans.size()) << what << "\n" << problems(r);
  const auto [d, area] = Geos().distance(r.plans, g.plans);
  EXPECT_LE(d, tolerance) << what << ": Hausdorff distance of the plans to the CityGML's";
  // Every boundary point within `tolerance`: the symmetric difference is at most a band that wide along
  // the boundaries (both sides).
  double perimeter = 0;
  for (const GroundPlan& p : g.plans)
    for (std::size_t k = 0; k < p.polygon.outer.size(); ++k) {
      const Point2& a = p.polygon.outer[k];
      const Point2& b = p.polygon.outer[(k + 1) % p.polygon.outer.size()];
      perimeter += std::hypot(b.x - a.x, b.y - a.y);
    }
  EXPECT_LE(area, 2 * perimeter * tolerance) << what << ": area of the symmetric difference (m²)";
}

// --- the tilesets against their CityGML -------------------------------------------------------------

TEST(Tiles3d, B3dmTilesetGivesTheCityGmlsPlansOneBuildingPerBatchId) {
  const gis::PipelineResult r = run(tiles("b3dm/tileset.json"));
  expect_plans_of_citygml(r, kFloat32Tolerance, "b3dm");
  EXPECT_EQ(r.footprints.size(), kBuildings) << problems(r);
  EXPECT_EQ(ids(r), building_ids());  // named by the batch table's gml_id
}

TEST(Tiles3d, FolderWithTilesetJsonAndExternalTilesetAreTheSameTileset) {
  const gis::PipelineResult folder = run(tiles("b3dm"));
  const gis::PipelineResult outer = run(tiles("b3dm/outer.json"));
  const gis::PipelineResult direct = run(tiles("b3dm/tileset.json"));
  EXPECT_EQ(test::plan_keys(folder.plans), test::plan_keys(direct.plans));
  EXPECT_EQ(test::plan_keys(outer.plans), test::plan_keys(direct.plans));
  EXPECT_EQ(outer.footprints.size(), kBuildings);
}

TEST(Tiles3d, UpgradedGlbTilesetWithMeshFeaturesAndPropertyTable) {
  // 3d-tiles-tools upgrade: b3dm -> glb with EXT_mesh_features (_FEATURE_ID_0) and EXT_structural_metadata (gml_id)
  const gis::PipelineResult r = run(tiles("glb/tileset.json"));
  expect_plans_of_citygml(r, kFloat32Tolerance, "glb 1.1");
  EXPECT_EQ(r.footprints.size(), kBuildings) << problems(r);
  EXPECT_EQ(ids(r), building_ids());
}

TEST(Tiles3d, DracoCompressedGlbTileset) {
  // gltf-pipeline -d with 24-bit positions: steps of 1.5 km / 2^24 = 0.09 mm, within the float32 tolerance.
  const gis::PipelineResult r = run(tiles("draco/tileset.json"));
  expect_plans_of_citygml(r, kFloat32Tolerance, "Draco");
  EXPECT_EQ(r.footprints.size(), kBuildings) << problems(r);
  EXPECT_EQ(ids(r), building_ids());
}

TEST(Tiles3d, MeshoptCompressedGlbOneBuildingPerNamedNode) {
  // gltfpack -c -noq: EXT_meshopt_compression of the float positions as they were (lossless).
  const gis::PipelineResult r = run(tiles("meshopt/nodes.json"));
  expect_plans_of_citygml(r, kFloat32Tolerance, "meshopt");
  EXPECT_EQ(r.footprints.size(), kBuildings) << problems(r);
  EXPECT_EQ(ids(r), building_ids());  // no feature ids: the named nodes
}

TEST(Tiles3d, QuantizedPositionsLandWithinHalfAStep) {
  // gltfpack -vp 16 -vpn: KHR_mesh_quantization, positions as 16-bit normalized integers over the city's
  // box (at most ~2 km across: steps of at most 2000 / 65535 = 3.1 cm), dequantized by the node transforms.
  // Every vertex lies within half a step on each axis (2.7 cm in 3D) of the b3dm's same building's.
  gis::ReadOptions opt;
  opt.target_srs = "EPSG:25832";
  const test::Read q = test::read(tiles("meshopt/quantized.json"), opt);
  const test::Read exact = test::read(tiles("b3dm/tileset.json"), opt);
  ASSERT_EQ(q.meshes.size(), kBuildings) << q.all();
  std::map<std::string, const Mesh*> by_id;
  for (const Mesh& m : exact.meshes) by_id[m.source_id] = &m;
  double worst = 0;
  for (const Mesh& m : q.meshes) {
    ASSERT_TRUE(by_id.count(m.source_id)) << m.source_id;
    for (const Point3& p : m.vertices) {
      double best = 1e300;
      for (const Point3& e : by_id[m.source_id]->vertices) best = std::min(best, std::hypot(p.x - e.x, p.y - e.y, p.z - e.z));
      worst = std::max(worst, best);
    }
  }
  EXPECT_LE(worst, 0.5 * 0.031 * std::sqrt(3.0));
  EXPECT_GT(worst, 1e-4);  // quantized indeed: not the float positions
}

TEST(Tiles3d, QuantizedPositionsKeepEveryBuildingsGround) {
  // The same buildings, quantized (quantized.json) and lossless (nodes.json): every vertex within 2.7 cm
  // (QuantizedPositionsLandWithinHalfAStep), so each footprint's boundary moves at most that far and its
  // area by at most its perimeter times that; the plans likewise. Quantization flips a few slivers of the
  // bottom of DENILD750000n8OW (a few cm² each) upside down; taking those as its whole bottom once lost
  // its 3,924 m² of ground without a problem.
  constexpr double kStep = 0.5 * 0.031 * 1.7320508075688772;  // half a step on each axis, in 3D
  const gis::PipelineResult q = run(tiles("meshopt/quantized.json"));
  const gis::PipelineResult lossless = run(tiles("meshopt/nodes.json"));
  ASSERT_EQ(q.footprints.size(), kBuildings) << problems(q);
  ASSERT_EQ(lossless.footprints.size(), kBuildings) << problems(lossless);
  for (const Problem& p : q.problems) EXPECT_EQ(p.code, "NOTE") << problems(q);
  const Geos g;
  std::map<std::string, std::pair<double, double>> exact;
  for (const Footprint& f : lossless.footprints) exact[f.source_id] = g.area_and_perimeter(f.polygons);
  double q_total = 0, exact_total = 0, perimeter_total = 0;
  for (const Footprint& f : q.footprints) {
    ASSERT_TRUE(exact.count(f.source_id)) << f.source_id;
    const auto [area, perimeter] = exact.at(f.source_id);
    const double a = g.area_and_perimeter(f.polygons).first;
    EXPECT_NEAR(a, area, perimeter * kStep) << f.source_id << ": footprint area against the lossless copy's";
    q_total += a;
    exact_total += area;
    perimeter_total += perimeter;
  }
  EXPECT_NEAR(q_total, exact_total, perimeter_total * kStep);
  // The plans: not by Hausdorff distance, since where two buildings share a wall each building's vertices
  // are quantized on its own, so a crack a few cm wide may open or close along it, and a crack's far end
  // lies metres from the other copy's boundary; by the area between them, a band of kStep along the
  // boundaries at most.
  const double area = g.distance(q.plans, lossless.plans).second;
  double perimeter = 0;
  for (const GroundPlan& p : lossless.plans) perimeter += g.area_and_perimeter({p.polygon}).second;
  EXPECT_LE(area, 2 * perimeter * kStep) << "area of the symmetric difference (m²)";
}

TEST(Tiles3d, KhrMeshoptCodecThisMeshoptimizerCannotDecodeIsAClearProblem) {
  // gltfpack -ce khr writes KHR_meshopt_compression with vertex codec version 1; Debian bookworm's
  // meshoptimizer 0.18 decodes version 0 only: each view is a problem saying so, never a crash.
  const test::Read r = test::read(tiles("meshopt/khr.json"));
  bool said = false;
  for (const Problem& p : r.problems) said = said || p.reason.find("meshopt codec version 1") != std::string::npos;
  EXPECT_TRUE(said) << r.all();
}

TEST(Tiles3d, MultipleContentsCompositeAndIdField) {
  // levels/west.b3dm and east.b3dm share the east-north-up frame of replace.json's root: as 1.1's two
  // contents of one tile, and as the two inner tiles of one cmpt (written here: a 16-byte header, the tiles).
  test::TempDir d("gp_3dtiles");
  const std::string west = slurp(tiles("levels/west.b3dm")), east = slurp(tiles("levels/east.b3dm"));
  d.file("west.b3dm", west);
  d.file("east.b3dm", east);
  std::string cmpt = "cmpt";
  for (std::uint32_t v : {1u, static_cast<std::uint32_t>(16 + west.size() + east.size()), 2u})
    cmpt.append(reinterpret_cast<const char*>(&v), 4);
  d.file("both.cmpt", cmpt + west + east);
  nlohmann::json ts = nlohmann::json::parse(slurp(tiles("levels/replace.json")));
  ts["asset"]["version"] = "1.1";
  ts["root"].erase("children");
  ts["root"].erase("content");
  ts["root"]["contents"] = nlohmann::json::array({{{"uri", "west.b3dm"}}, {{"uri", "east.b3dm"}}});
  const gis::PipelineResult multiple = run(d.file("multiple.json", ts.dump()));
  EXPECT_EQ(multiple.footprints.size(), kBuildings) << problems(multiple);
  EXPECT_EQ(ids(multiple), building_ids());
  expect_plans_of_citygml(multiple, kFloat32Tolerance, "multiple contents");
  ts["root"].erase("contents");
  ts["root"]["content"] = {{"uri", "both.cmpt"}};
  const gis::PipelineResult composite = run(d.file("composite.json", ts.dump()));
  EXPECT_EQ(composite.footprints.size(), kBuildings) << problems(composite);
  EXPECT_EQ(ids(composite), building_ids());
  EXPECT_EQ(test::plan_keys(composite.plans), test::plan_keys(multiple.plans));
  // --id-field naming a property the batch tables lack: the buildings are "<tile uri>#<batch id>".
  const gis::PipelineResult unnamed = run((d.path / "composite.json").string(), "height");
  ASSERT_EQ(unnamed.footprints.size(), kBuildings);
  for (const Footprint& f : unnamed.footprints) EXPECT_EQ(f.source_id.rfind("both.cmpt/", 0), 0u) << f.source_id;
  EXPECT_EQ(ids(run((d.path / "composite.json").string(), "gml_id")), building_ids());
}

TEST(Tiles3d, NoFeatureIdsIsSaidInANote) {
  const gis::PipelineResult r = run(tiles("meshopt/nodes.json"));
  bool note = false;
  for (const Problem& p : r.problems)
    note = note || (p.code == "NOTE" && p.reason.find("no feature ids") != std::string::npos);
  EXPECT_TRUE(note) << problems(r);
}

// --- levels of detail -------------------------------------------------------------------------------

TEST(Tiles3d, ReplaceTakesTheLeavesAndCountsEachBuildingOnce) {
  // all.b3dm (every building) in the parent, west and east halves in the children, REPLACE.
  const gis::PipelineResult r = run(tiles("levels/replace.json"));
  EXPECT_EQ(r.footprints.size(), kBuildings) << problems(r);
  EXPECT_EQ(ids(r), building_ids());
  expect_plans_of_citygml(r, kFloat32Tolerance, "replace");
}

TEST(Tiles3d, AddTakesEveryLevel) {
  // west.b3dm in the parent, east.b3dm in the child, ADD: both.
  const gis::PipelineResult r = run(tiles("levels/add.json"));
  EXPECT_EQ(r.footprints.size(), kBuildings) << problems(r);
  expect_plans_of_citygml(r, kFloat32Tolerance, "add");
}

/// The mean of a mesh's vertices in plan.
Point2 centre(const Mesh& m) {
  Point2 c{0, 0};
  for (const Point3& v : m.vertices) c = Point2{c.x + v.x / m.vertices.size(), c.y + v.y / m.vertices.size()};
  return c;
}

TEST(Tiles3d, AddCountsEachBuildingOnceTheFinerCopy) {
  // ADD with the whole city in the parent and the west half again in the child, moved 5 km east by the
  // child's transform so that the two copies differ: every building once, the west ones from the child
  // (the finer level), each coarser copy left out in a NOTE naming the building and both tiles.
  test::TempDir d("gp_3dtiles");
  d.file("all.b3dm", slurp(tiles("levels/all.b3dm")));
  d.file("west.b3dm", slurp(tiles("levels/west.b3dm")));
  nlohmann::json ts = nlohmann::json::parse(slurp(tiles("levels/add.json")));
  ts["root"]["content"]["uri"] = "all.b3dm";
  ts["root"]["children"][0]["content"]["uri"] = "west.b3dm";
  ts["root"]["children"][0]["transform"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5000, 0, 0, 1};
  gis::ReadOptions opt;
  opt.target_srs = "EPSG:25832";
  const test::Read r = test::read(d.file("add.json", ts.dump()), opt);
  ts["root"].erase("children");
  const test::Read parent = test::read(d.file("parent.json", ts.dump()), opt);
  ASSERT_EQ(parent.meshes.size(), kBuildings) << parent.all();

  std::map<std::string, Point2> coarse, kept;
  for (const Mesh& m : parent.meshes) coarse[m.source_id] = centre(m);
  for (const Mesh& m : r.meshes) EXPECT_TRUE(kept.emplace(m.source_id, centre(m)).second) << m.source_id << " twice";
  EXPECT_EQ(r.meshes.size(), kBuildings) << r.all();
  std::set<std::string> kept_ids;
  for (const auto& [id, c] : kept) kept_ids.insert(id);
  EXPECT_EQ(kept_ids, building_ids());
  std::size_t moved = 0;
  for (const auto& [id, c] : kept) {
    const double east = c.x - coarse.at(id).x;
    EXPECT_TRUE(std::abs(east) < 1 || std::abs(east - 5000) < 50) << id << " moved " << east << " m";
    moved += std::abs(east - 5000) < 50;
  }
  EXPECT_EQ(moved, 40u) << "the west buildings are the child's copies";
  EXPECT_EQ(r.count("DUPLICATE_ID"), 0u) << r.all();
  EXPECT_EQ(r.info.tiles3d.coarser_copies_left_out, 40u);
  std::size_t notes = 0;
  for (const Problem& p : r.problems)
    if (p.code == "NOTE" && p.reason.find("coarser one is left out") != std::string::npos) {
      ++notes;
      EXPECT_NE(p.file.find("all.b3dm"), std::string::npos) << p.file;
      EXPECT_NE(p.reason.find("\"" + p.source_id + "\""), std::string::npos) << p.reason;
      EXPECT_NE(p.reason.find("west.b3dm"), std::string::npos) << p.reason;
      EXPECT_NEAR(kept.at(p.source_id).x - coarse.at(p.source_id).x, 5000, 50) << p.source_id;
    }
  EXPECT_EQ(notes, 40u) << r.all();
}

TEST(Tiles3d, TheSameBuildingInTwoNeighbouringTilesIsSaid) {
  // Two sibling tiles holding the same buildings (a building cut between tiles looks so): neither is finer,
  // both copies are read and each repeat is a DUPLICATE_ID problem naming the building.
  test::TempDir d("gp_3dtiles");
  d.file("west.b3dm", slurp(tiles("levels/west.b3dm")));
  d.file("again.b3dm", slurp(tiles("levels/west.b3dm")));
  nlohmann::json ts = nlohmann::json::parse(slurp(tiles("levels/replace.json")));
  ts["root"]["children"][0]["content"]["uri"] = "west.b3dm";
  ts["root"]["children"][1]["content"]["uri"] = "again.b3dm";
  const test::Read r = test::read(d.file("siblings.json", ts.dump()));
  EXPECT_EQ(r.meshes.size(), 80u);
  EXPECT_EQ(r.count("DUPLICATE_ID"), 40u) << r.all();
  EXPECT_EQ(r.info.tiles3d.coarser_copies_left_out, 0u);
  for (const Problem& p : r.problems)
    if (p.code == "DUPLICATE_ID") {
      EXPECT_NE(p.reason.find(p.source_id), std::string::npos) << p.reason;
    }
}

TEST(Tiles3d, ACoarserCopyIsLeftOutWhateverElseGaveTheBuilding) {
  // ADD: tile A (west) with child A1 (west again), and in another branch B2, three levels down (west again).
  // Deepest first: B2, A1 (not below B2's tile: both read, DUPLICATE_ID), then A, above A1: left out.
  test::TempDir d("gp_3dtiles");
  for (const char* name : {"a.b3dm", "a1.b3dm", "b2.b3dm"}) d.file(name, slurp(tiles("levels/west.b3dm")));
  nlohmann::json ts = nlohmann::json::parse(slurp(tiles("levels/replace.json")));
  ts["root"]["refine"] = "ADD";
  ts["root"].erase("content");
  const nlohmann::json leaf = ts["root"]["children"][0];  // bounding volume, geometricError 0, a content
  auto tile = [&](const char* uri, nlohmann::json children) {
    nlohmann::json t = leaf;
    t["geometricError"] = 1;
    if (uri) t["content"]["uri"] = uri;
    else t.erase("content");
    t["children"] = std::move(children);
    return t;
  };
  nlohmann::json a1 = leaf, b2 = leaf;
  a1["content"]["uri"] = "a1.b3dm";
  b2["content"]["uri"] = "b2.b3dm";
  ts["root"]["children"] = {tile("a.b3dm", {a1}), tile(nullptr, {tile(nullptr, {b2})})};
  const test::Read r = test::read(d.file("branches.json", ts.dump()));
  EXPECT_EQ(r.meshes.size(), 80u) << r.all();
  EXPECT_EQ(r.count("DUPLICATE_ID"), 40u) << r.all();
  EXPECT_EQ(r.info.tiles3d.coarser_copies_left_out, 40u) << r.all();
  for (const Problem& p : r.problems) {
    if (p.code == "DUPLICATE_ID") EXPECT_NE(p.file.find("a1.b3dm"), std::string::npos) << p.file;
    if (p.code == "NOTE" && p.reason.find("left out") != std::string::npos) {
      EXPECT_NE(p.file.find("a.b3dm"), std::string::npos) << p.file;
      EXPECT_NE(p.reason.find("a1.b3dm"), std::string::npos) << p.reason;
    }
  }
}

TEST(Tiles3d, GeometricErrorChoosesTheLevel) {
  // The parent's geometricError is 500: allowing 600 m stops there (all.b3dm), 100 m goes down to the leaves.
  CPLSetConfigOption("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", "600");
  gis::ReadOptions opt;
  opt.target_srs = "EPSG:25832";
  const test::Read coarse = test::read(tiles("levels/replace.json"), opt);
  CPLSetConfigOption("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", "100");
  const test::Read fine = test::read(tiles("levels/replace.json"), opt);
  CPLSetConfigOption("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", "many");
  EXPECT_THROW(test::read(tiles("levels/replace.json"), opt), InvalidArgument);
  CPLSetConfigOption("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", nullptr);
  EXPECT_EQ(coarse.meshes.size(), kBuildings);
  EXPECT_EQ(coarse.info.tiles3d.contents, 1u);
  EXPECT_EQ(coarse.info.tiles3d.skipped_by_level, 0u);
  EXPECT_EQ(fine.meshes.size(), kBuildings);
  EXPECT_EQ(fine.info.tiles3d.contents, 2u);
  EXPECT_EQ(fine.info.tiles3d.skipped_by_level, 1u);
}

TEST(Tiles3d, ImplicitQuadtreeTakesTheAvailableLeaves) {
  // implicit/: QUADTREE, 2 levels in one binary subtree; level 0 every building, level 1 three quadrants
  // (tile x 0, y 1 not available: its buildings are in tile 0, 0).
  const gis::PipelineResult r = run(tiles("implicit/tileset.json"));
  EXPECT_EQ(r.footprints.size(), kBuildings) << problems(r);
  EXPECT_EQ(ids(r), building_ids());
  expect_plans_of_citygml(r, kFloat32Tolerance, "implicit");
  gis::ReadOptions opt;
  const test::Read leaves = test::read(tiles("implicit/tileset.json"), opt);
  EXPECT_EQ(leaves.info.tiles3d.contents, 3u);
  EXPECT_EQ(leaves.info.tiles3d.skipped_by_level, 1u);
  EXPECT_EQ(leaves.info.tiles3d.tiles, 4u);
  // The root's geometricError is 500, level 1's 250: 600 m stops at the root.
  CPLSetConfigOption("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", "600");
  const test::Read root = test::read(tiles("implicit/tileset.json"), opt);
  CPLSetConfigOption("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", nullptr);
  EXPECT_EQ(root.info.tiles3d.contents, 1u);
  EXPECT_EQ(root.meshes.size(), kBuildings);
}

TEST(Tiles3dHostile, ShortBitstreamsAndBadSubtreesAreProblems) {
  test::TempDir d("gp_3dtiles");
  const nlohmann::json ts = nlohmann::json::parse(slurp(tiles("implicit/tileset.json")));
  d.file("tileset.json", ts.dump());
  d.file("content/0/0/0.b3dm", slurp(tiles("implicit/content/0/0/0.b3dm")));
  auto subtree_says = [&](const std::string& subtree, const std::string& what) {
    d.file("subtrees/0/0/0.subtree", subtree);
    const test::Read r = test::read((d.path / "tileset.json").string());
    bool said = false;
    for (const Problem& p : r.problems)
      said = said || (p.code == "UNREADABLE_SUBTREE" && p.reason.find(what) != std::string::npos);
    EXPECT_TRUE(said) << what << "\n" << r.all();
    EXPECT_TRUE(r.meshes.empty());
  };
  // A JSON subtree whose tile availability bitstream has 0 bytes for its 5 tiles.
  d.file("subtrees/0/0/a.bin", std::string(1, '\x1f'));  // a subtree's buffer uri is relative to the subtree
  subtree_says(R"({"buffers":[{"uri":"a.bin","byteLength":1}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":0}],)"
               R"("tileAvailability":{"bitstream":0},"childSubtreeAvailability":{"constant":0}})",
               "short bitstream");
  // A binary subtree whose header claims more JSON than there is, and one cut inside its header.
  const std::string good = slurp(tiles("implicit/subtrees/0/0/0.subtree"));
  std::string lying = good;
  const std::uint64_t huge = 1ull << 40;
  std::memcpy(lying.data() + 8, &huge, 8);
  subtree_says(lying, "the file has");
  subtree_says(good.substr(0, 10), "truncated subtree");
  // A bufferView past its buffer; a buffer outside the tileset's folder.
  subtree_says(R"({"buffers":[{"uri":"a.bin","byteLength":1}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":9}],)"
               R"("tileAvailability":{"bitstream":0},"childSubtreeAvailability":{"constant":0}})",
               "reaches past its buffer");
  subtree_says(R"({"buffers":[{"uri":"../../../../a.bin","byteLength":1}],"bufferViews":[],)"
               R"("tileAvailability":{"constant":1},"childSubtreeAvailability":{"constant":0}})",
               "is not read");
  // Absurd levels: a problem, not 4^30 loops.
  nlohmann::json deep = ts;
  deep["root"]["implicitTiling"]["subtreeLevels"] = 30;
  const test::Read r = test::read(d.file("tileset.json", deep.dump()));
  EXPECT_EQ(r.count("BAD_TILE"), 1u) << r.all();
}

TEST(Tiles3d, GpuInstancingGlbIsTheI3dmsInstances) {
  // i3dm_glb/: 3d-tiles-tools' upgrade of instances.i3dm: a glb with EXT_mesh_gpu_instancing (required) and
  // EXT_instance_features naming each instance through a property table. The same two buildings, where the
  // i3dm puts them (1 mm: both float32 stores of the same numbers).
  gis::ReadOptions opt;
  opt.target_srs = "EPSG:25832";
  const test::Read glb = test::read(tiles("i3dm_glb/tileset.json"), opt);
  const test::Read i3dm = test::read(tiles("i3dm/tileset.json"), opt);
  ASSERT_EQ(glb.meshes.size(), 2u) << glb.all();
  ASSERT_EQ(i3dm.meshes.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(glb.meshes[k].source_id, i3dm.meshes[k].source_id);
    double worst = 0;
    for (const Point3& p : glb.meshes[k].vertices) {
      double best = 1e300;
      for (const Point3& q : i3dm.meshes[k].vertices) best = std::min(best, std::hypot(p.x - q.x, p.y - q.y, p.z - q.z));
      worst = std::max(worst, best);
    }
    EXPECT_LE(worst, 1e-3) << glb.meshes[k].source_id;
  }
}

// --- georeference -----------------------------------------------------------------------------------

TEST(Tiles3d, VerticesLandWherePyprojPutsThem) {
  // georef_check.json: vertices of one building as stored in b3dm/west.b3dm, each with the EPSG:25832
  // position pyproj computed from those stored numbers (ENU -> ECEF -> EPSG:25832) in make_tilesets.py.
  const nlohmann::json check = nlohmann::json::parse(slurp(tiles("georef_check.json")));
  gis::ReadOptions opt;
  opt.target_srs = "EPSG:25832";
  const test::Read r = test::read(tiles("b3dm/tileset.json"), opt);
  const Mesh* m = nullptr;
  for (const Mesh& mesh : r.meshes)
    if (mesh.source_id == check["building"].get<std::string>()) m = &mesh;
  ASSERT_NE(m, nullptr);
  ASSERT_GE(check["vertices"].size(), 3u);
  for (const auto& v : check["vertices"]) {
    const double x = v["epsg25832"][0].get<double>(), y = v["epsg25832"][1].get<double>(), z = v["epsg25832"][2].get<double>();
    double best = 1e300;
    for (const Point3& p : m->vertices) best = std::min(best, std::hypot(p.x - x, p.y - y, p.z - z));
    EXPECT_LE(best, 1e-3) << "vertex " << v.dump();  // mm-precise
  }
}

TEST(Tiles3d, I3dmInstancesEastNorthUpNamedByTheirBatchIds) {
  // instances.i3dm: one building's model (east-north-up at its centre, y-up) instanced at RTC_CENTER = that
  // centre and 100 m east of it, EAST_NORTH_UP, BATCH_ID 0 and 1, batch table gml_id. Instance 0 lies where
  // the b3dm puts the same building (1 mm); instance 1 is instance 0 moved by pyproj's EPSG:25832 image of
  // the 100 m (georef_check.json; the east-north-up frame turns by 100 m / 6378 km = 16 µrad between the two:
  // 0.3 mm over the building, so 2 mm).
  const nlohmann::json check = nlohmann::json::parse(slurp(tiles("georef_check.json")))["i3dm"];
  gis::ReadOptions opt;
  opt.target_srs = "EPSG:25832";
  const test::Read r = test::read(tiles("i3dm/tileset.json"), opt);
  const test::Read exact = test::read(tiles("b3dm/tileset.json"), opt);
  ASSERT_EQ(r.meshes.size(), 2u) << r.all();
  EXPECT_EQ(r.meshes[0].source_id, check["building"].get<std::string>());
  EXPECT_EQ(r.meshes[1].source_id, check["copy"].get<std::string>());
  const Mesh* ref = nullptr;
  for (const Mesh& m : exact.meshes)
    if (m.source_id == r.meshes[0].source_id) ref = &m;
  ASSERT_NE(ref, nullptr);
  auto farthest = [](const Mesh& a, const Mesh& b, double dx, double dy, double dz) {
    double worst = 0;
    for (const Point3& p : a.vertices) {
      double best = 1e300;
      for (const Point3& q : b.vertices) best = std::min(best, std::hypot(p.x + dx - q.x, p.y + dy - q.y, p.z + dz - q.z));
      worst = std::max(worst, best);
    }
    return worst;
  };
  EXPECT_LE(farthest(r.meshes[0], *ref, 0, 0, 0), 1e-3);
  EXPECT_LE(farthest(*ref, r.meshes[0], 0, 0, 0), 1e-3);
  const auto& d = check["offset_epsg25832"];
  EXPECT_LE(farthest(r.meshes[0], r.meshes[1], d[0].get<double>(), d[1].get<double>(), d[2].get<double>()), 2e-3);
}

// --- hostile input ----------------------------------------------------------------------------------

std::string tileset_with(const std::string& root) {
  return R"({"asset":{"version":"1.0"},"geometricError":10,"root":)" + root + "}";
}

std::string leaf(const std::string& uri, const std::string& extra = "") {
  return R"({"geometricError":0,"boundingVolume":{"sphere":[0,0,0,1]},"content":{"uri":")" + uri + "\"}" + extra + "}";
}

TEST(Tiles3dHostile, UrisOutsideTheTilesetOrOnTheNetworkAreNeverRead) {
  test::TempDir d("gp_3dtiles");
  const std::string west = slurp(tiles("b3dm/west.b3dm"));
  d.file("outside.b3dm", west);  // a readable tile, but outside the tileset's folder
  d.file("set/west.b3dm", west);
  const std::string enu = nlohmann::json::parse(slurp(tiles("levels/replace.json")))["root"]["transform"].dump();
  const std::string path = d.file("set/tileset.json", tileset_with(
      R"({"geometricError":10,"refine":"ADD","transform":)" + enu + R"(,"children":[)" +
      leaf("http://example.com/a.b3dm") + "," + leaf("../outside.b3dm") + "," + leaf("/etc/passwd") + "," +
      leaf("sub/..%2F..%2Foutside.b3dm") + "," + leaf("west.b3dm") + "]}"));
  const test::Read r = test::read(path);
  EXPECT_EQ(r.count("NETWORK_URI"), 1u) << r.all();
  EXPECT_EQ(r.count("OUTSIDE_TILESET"), 3u) << r.all();
  EXPECT_EQ(r.meshes.size(), 40u) << r.all();  // west.b3dm, read once
}

TEST(Tiles3dHostile, CyclicExternalTilesetsAndAbsurdTransformsAreProblems) {
  test::TempDir d("gp_3dtiles");
  d.file("a.json", tileset_with(leaf("b.json")));
  d.file("b.json", tileset_with(leaf("a.json")));
  const test::Read cyc = test::read((d.path / "a.json").string());
  EXPECT_EQ(cyc.count("TILESET_CYCLE"), 1u) << cyc.all();

  d.file("west.b3dm", slurp(tiles("b3dm/west.b3dm")));
  for (const char* t : {R"([1,0,0,0,0,1,0,0,0,0,1,0,1e300,0,0,1])", R"([1,0,0,0,0,1,0,0,0,0,1,0,0,0,0])",
                               R"([1e9,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1])", R"([1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,2])"}) {
    const std::string p = d.file("t.json", tileset_with(leaf("west.b3dm", std::string(",\"transform\":") + t)));
    const test::Read r = test::read(p);
    EXPECT_EQ(r.count("BAD_TRANSFORM"), 1u) << t << "\n" << r.all();
    EXPECT_TRUE(r.meshes.empty());
  }
}

TEST(Tiles3dHostile, TruncatedAndLyingB3dmAreProblemsNamingTheTile) {
  test::TempDir d("gp_3dtiles");
  const std::string b = slurp(tiles("b3dm/west.b3dm"));
  auto with_u32 = [&](std::string s, std::size_t at, std::uint32_t v) {
    std::memcpy(s.data() + at, &v, 4);
    return s;
  };
  // name, bytes, what the problem must say
  const std::vector<std::array<std::string, 3>> cases = {
      {"short.b3dm", b.substr(0, 20), "truncated b3dm"},                       // header cut
      {"cut.b3dm", b.substr(0, b.size() / 2), "says " + std::to_string(b.size()) + " bytes"},  // byteLength > file
      {"ft.b3dm", with_u32(b, 12, 0x7fffffff), "reach past its byteLength"},  // feature table length lies
      {"bt.b3dm", with_u32(b, 20, 0x20000000), "reach past its byteLength"},  // batch table length lies
      {"ver.b3dm", with_u32(b, 4, 7), "version 7"},                            // unknown version
      {"glb.b3dm", with_u32(b, 8, static_cast<std::uint32_t>(b.size() - 100)), "glTF"},  // glb cut inside
      {"cmpt.cmpt", std::string("cmpt") + std::string("\1\0\0\0", 4) + std::string("\x20\0\0\0", 4) +
                        std::string("\5\0\0\0", 4) + std::string(16, 'x'), "cmpt inner tile"},  // inner tiles past its end
      {"i3dm.i3dm", "i3dm" + std::string(40, '\0'), "i3dm version 0"},
      {"pnts.pnts", "pnts" + std::string(40, '\0'), "not read"}};
  // The tiles under the east-north-up transform that places west.b3dm, beside a good copy of it.
  const std::string enu = nlohmann::json::parse(slurp(tiles("levels/replace.json")))["root"]["transform"].dump();
  d.file("good.b3dm", b);
  std::string children = leaf("good.b3dm");
  for (const auto& c : cases) {
    d.file(c[0], c[1]);
    children += "," + leaf(c[0]);
  }
  const std::string p = d.file("tileset.json", tileset_with(R"({"geometricError":1,"refine":"ADD","transform":)" + enu +
                                                              R"(,"children":[)" + children + "]}"));
  const test::Read r = test::read(p);
  EXPECT_EQ(r.meshes.size(), 40u) << r.all();  // the good tile
  EXPECT_EQ(r.count("UNREADABLE_TILE"), cases.size()) << r.all();
  for (const auto& c : cases) {
    bool named = false;
    for (const Problem& pr : r.problems)
      named = named || (pr.code == "UNREADABLE_TILE" && pr.file.find(c[0]) != std::string::npos &&
                        pr.reason.find(c[2]) != std::string::npos);
    EXPECT_TRUE(named) << c[0] << " should say \"" << c[2] << "\"\n" << r.all();
  }
  // The same tiles given alone (placed at an origin: they have no transform): an InputError naming the
  // file, never a crash; the good tile reads.
  gis::ReadOptions opt;
  opt.origin = "7.6,52.9,0";
  EXPECT_EQ(test::read((d.path / "good.b3dm").string(), opt).meshes.size(), 40u);
  for (const auto& c : cases) {
    try {
      test::read((d.path / c[0]).string(), opt);
      ADD_FAILURE() << c[0] << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c[0]), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c[2]), std::string::npos) << e.what();
    }
  }
}

TEST(GltfCompressed, UnknownRequiredExtensionIsRefusedByName) {
  test::TempDir d("gp_gltf");
  std::string glb = slurp(tiles("meshopt/nodes.glb"));
  const std::size_t at = glb.find("\"extensionsRequired\":[\"");
  ASSERT_NE(at, std::string::npos);
  glb.replace(at + 23, 14, "EXT_unknown_xy");  // "KHR_mesh_quant" -> same length
  const std::string p = d.file("x.glb", glb);
  try {
    test::read(p);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("EXT_unknown_xy"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace groundplan

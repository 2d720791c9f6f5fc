// SPDX-License-Identifier: MIT
// The OGR reader (issue 22) on small sources in /vsimem: what each geometry becomes (footprint faces,
// solid faces, a Problem), ids and grouping, the CRS handed on, and read_any's dispatch. Runs in the
// sanitizer build too (the e2e tests there cover only the bad-input corpus).
#include <groundplan/error.h>
#include <groundplan/gis/ogr_input.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/reader.h>

#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <vector>

namespace groundplan::gis {
namespace {

void put(const std::string& path, const std::string& text) {
  VSILFILE* f = VSIFOpenL(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(VSIFWriteL(text.data(), 1, text.size(), f), text.size());
  VSIFCloseL(f);
}

// A square footprint, a cube as MultiPolygon Z (bottom, top, four walls), a line, a null and an empty
// geometry, two parts of one building ("b") in EPSG:25832.
const char* kGeoJson = R"({"type": "FeatureCollection",
 "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::25832"}},
 "features": [
  {"type": "Feature", "properties": {"name": "square", "bldg": "a"},
   "geometry": {"type": "Polygon", "coordinates": [[[400000,5800000],[400010,5800000],[400010,5800010],[400000,5800010],[400000,5800000]]]}},
  {"type": "Feature", "properties": {"name": "cube", "bldg": "c"},
   "geometry": {"type": "MultiPolygon", "coordinates": [
     [[[400100,5800000,0],[400100,5800010,0],[400110,5800010,0],[400110,5800000,0],[400100,5800000,0]]],
     [[[400100,5800000,5],[400110,5800000,5],[400110,5800010,5],[400100,5800010,5],[400100,5800000,5]]],
     [[[400100,5800000,0],[400110,5800000,0],[400110,5800000,5],[400100,5800000,5],[400100,5800000,0]]],
     [[[400110,5800000,0],[400110,5800010,0],[400110,5800010,5],[400110,5800000,5],[400110,5800000,0]]],
     [[[400110,5800010,0],[400100,5800010,0],[400100,5800010,5],[400110,5800010,5],[400110,5800010,0]]],
     [[[400100,5800010,0],[400100,5800000,0],[400100,5800000,5],[400100,5800010,5],[400100,5800010,0]]]]}},
  {"type": "Feature", "properties": {"name": "line", "bldg": "l"},
   "geometry": {"type": "LineString", "coordinates": [[400000,5800100],[400050,5800100]]}},
  {"type": "Feature", "properties": {"name": "null", "bldg": "n"}, "geometry": null},
  {"type": "Feature", "properties": {"name": "part1", "bldg": "b"},
   "geometry": {"type": "Polygon", "coordinates": [[[400200,5800000],[400210,5800000],[400210,5800010],[400200,5800000]]]}},
  {"type": "Feature", "properties": {"name": "part2", "bldg": "b"},
   "geometry": {"type": "Polygon", "coordinates": [[[400205,5800000],[400215,5800000],[400215,5800010],[400205,5800000]]]}}
 ]})";

struct Read {
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  OgrInfo info;
  bool srs_ready_before_first_mesh = false;
};

Read read(const std::string& path, const OgrInputOptions& o = {}) {
  Read r;
  bool ready = false;
  read_ogr(path, o, [&] { ready = true; }, [&](Mesh&& m) {
    if (r.meshes.empty()) r.srs_ready_before_first_mesh = ready;
    r.meshes.push_back(std::move(m));
  }, r.problems, r.info);
  return r;
}

std::map<std::string, std::string> codes(const std::vector<Problem>& ps) {
  std::map<std::string, std::string> out;
  for (const Problem& p : ps)
    if (p.code != "NOTE") out[p.source_id] = p.code;
  return out;
}

TEST(OgrReader, EachGeometryBecomesAFootprintASolidOrANamedProblem) {
  const std::string path = "/vsimem/ogr_reader_test/a.geojson";
  put(path, kGeoJson);
  OgrInputOptions o;
  o.id_field = "name";
  const Read r = read(path, o);
  EXPECT_TRUE(r.srs_ready_before_first_mesh);
  EXPECT_EQ(r.info.source_srs, "EPSG:25832");
  EXPECT_TRUE(r.info.east_north);
  EXPECT_EQ(r.info.driver, "GeoJSON");
  ASSERT_EQ(r.meshes.size(), 4u);
  EXPECT_EQ(r.meshes[0].source_id, "square");
  ASSERT_EQ(r.meshes[0].faces.size(), 1u);
  EXPECT_EQ(r.meshes[0].faces[0].kind, SurfaceKind::FootPrint);
  EXPECT_EQ(r.meshes[0].ring_offsets.back(), 4u);  // the closing vertex is not repeated
  EXPECT_EQ(r.meshes[1].source_id, "cube");
  ASSERT_EQ(r.meshes[1].faces.size(), 6u);
  for (const MeshFace& f : r.meshes[1].faces) EXPECT_EQ(f.kind, SurfaceKind::Unknown);
  EXPECT_EQ(codes(r.problems), (std::map<std::string, std::string>{{"line", "NOT_AREAL"}, {"null", "EMPTY_GEOMETRY"}}));
  for (const Problem& p : r.problems) {
    EXPECT_EQ(p.file, path);
    EXPECT_NE(p.reason.find("layer 'a', FID "), std::string::npos) << p.reason;
  }
  EXPECT_EQ(r.info.features, 6u);
  EXPECT_EQ(r.info.features_bad, 2u);
  VSIUnlink(path.c_str());
}

TEST(OgrReader, GroupByMakesOneBuildingOfTheFeaturesSharingAValue) {
  const std::string path = "/vsimem/ogr_reader_test/g.geojson";
  put(path, kGeoJson);
  OgrInputOptions o;
  o.group_by = "bldg";
  const Read r = read(path, o);
  std::map<std::string, std::size_t> faces;
  for (const Mesh& m : r.meshes) faces[m.source_id] = m.faces.size();
  EXPECT_EQ(faces, (std::map<std::string, std::size_t>{{"a", 1}, {"b", 2}, {"c", 6}}));
  EXPECT_EQ(codes(r.problems), (std::map<std::string, std::string>{{"l", "NOT_AREAL"}, {"n", "EMPTY_GEOMETRY"}}));
  VSIUnlink(path.c_str());
}

TEST(OgrReader, NanAndHugeCoordinatesAreProblemsAndTheRestIsRead) {
  GDALAllRegister();
  const std::string path = "/vsimem/ogr_reader_test/bad.fgb";
  {
    GDALDriver* drv = GetGDALDriverManager()->GetDriverByName("FlatGeobuf");
    ASSERT_NE(drv, nullptr);
    GDALDataset* ds = drv->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
    ASSERT_NE(ds, nullptr);
    OGRSpatialReference srs;
    srs.importFromEPSG(25832);
    OGRLayer* l = ds->CreateLayer("bad", &srs, wkbPolygon, nullptr);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double xs[3][2] = {{400000, 400010}, {nan, 400010}, {1e15, 400010}};
    for (const auto& x : xs) {
      OGRPolygon poly;
      OGRLinearRing ring;
      ring.addPoint(x[0], 5800000);
      ring.addPoint(x[1], 5800000);
      ring.addPoint(x[1], 5800010);
      ring.addPoint(x[0], 5800000);
      poly.addRing(&ring);
      OGRFeature f(l->GetLayerDefn());
      f.SetGeometry(&poly);
      ASSERT_EQ(l->CreateFeature(&f), OGRERR_NONE);
    }
    GDALClose(ds);
  }
  const Read r = read(path);
  ASSERT_EQ(r.meshes.size(), 1u);
  EXPECT_EQ(r.meshes[0].source_id, "0");
  EXPECT_EQ(codes(r.problems), (std::map<std::string, std::string>{{"1", "BAD_COORDINATES"}, {"2", "COORDINATE_OUT_OF_RANGE"}}));
  VSIUnlink(path.c_str());
}

TEST(OgrReader, ReadAnyDispatchesByContentAndThePipelinePlacesTheLayer) {
  const std::string path = "/vsimem/ogr_reader_test/no_extension";
  put(path, kGeoJson);
  EXPECT_EQ(detect_format(path), InputFormat::Unknown);  // not a city format ...
  EXPECT_TRUE(ogr_can_read(path));                        // ... but GDAL knows it
  ReadInfo info;
  std::vector<Problem> problems;
  std::size_t meshes = 0;
  read_any(path, ReadOptions{}, [&](Mesh&&) { ++meshes; }, problems, info);
  EXPECT_EQ(info.format, InputFormat::Ogr);
  EXPECT_FALSE(info.in_working_crs);
  EXPECT_EQ(info.source_srs, "EPSG:25832");
  EXPECT_EQ(info.source_axis, AxisOrder::EastNorth);
  EXPECT_EQ(meshes, 4u);  // the line and the null geometry are problems

  PipelineOptions po;
  po.inputs = {path};
  const PipelineResult res = run_pipeline(po);
  EXPECT_EQ(res.crs_name, "EPSG:25832");
  EXPECT_EQ(res.footprints.size(), 4u);   // square, cube (its bottom), part1, part2
  EXPECT_EQ(res.plans.size(), 3u);        // the parts overlap
  EXPECT_EQ(res.buildings_read, 6u);      // and two problems: nothing lost
  EXPECT_EQ(res.buildings_dropped, 2u);
  VSIUnlink(path.c_str());

  put(path, "neither a city model nor anything GDAL reads\n");
  EXPECT_FALSE(ogr_can_read(path));
  EXPECT_THROW(read_any(path, ReadOptions{}, [](Mesh&&) {}, problems, info), InputError);
  VSIUnlink(path.c_str());
}

TEST(OgrReader, TwoFilesReadAtOnceOnTwoThreadsGiveWhatEachGivesAlone) {
  // The lead's parallel reading: one read_ogr per file and thread, each with its own dataset handle.
  const std::string a = "/vsimem/ogr_reader_test/t1.geojson", b = "/vsimem/ogr_reader_test/t2.geojson";
  put(a, kGeoJson);
  std::string other = kGeoJson;  // the same features in EPSG:4326 would need another file; ids differ instead
  other.replace(other.find("\"square\""), 8, "\"carre_\"");
  put(b, other);
  OgrInputOptions o;
  o.id_field = "name";
  const Read alone_a = read(a, o), alone_b = read(b, o);
  for (int round = 0; round < 20; ++round) {
    Read ra, rb;
    std::thread ta([&] { ra = read(a, o); });
    std::thread tb([&] { rb = read(b, o); });
    ta.join();
    tb.join();
    ASSERT_EQ(ra.meshes.size(), alone_a.meshes.size());
    ASSERT_EQ(rb.meshes.size(), alone_b.meshes.size());
    for (std::size_t i = 0; i < ra.meshes.size(); ++i) {
      EXPECT_EQ(ra.meshes[i].source_id, alone_a.meshes[i].source_id);
      EXPECT_EQ(ra.meshes[i].vertices, alone_a.meshes[i].vertices);
    }
    for (std::size_t i = 0; i < rb.meshes.size(); ++i) {
      EXPECT_EQ(rb.meshes[i].source_id, alone_b.meshes[i].source_id);
      EXPECT_EQ(rb.meshes[i].vertices, alone_b.meshes[i].vertices);
    }
    EXPECT_EQ(codes(ra.problems), codes(alone_a.problems));
    EXPECT_EQ(codes(rb.problems), codes(alone_b.problems));
  }
  EXPECT_EQ(alone_b.meshes[0].source_id, "carre_");
  VSIUnlink(a.c_str());
  VSIUnlink(b.c_str());
}

TEST(OgrReader, AZippedShapefileIsNoKmz) {
  const std::string zip_head("PK\x03\x04\x14\x00", 6);
  EXPECT_EQ(detect_format("parts.shp.zip", zip_head), InputFormat::Unknown);  // left to GDAL
  EXPECT_EQ(detect_format("parts.shz", zip_head), InputFormat::Unknown);
  EXPECT_EQ(detect_format("model", zip_head), InputFormat::Kmz);              // a KMZ without its extension
  EXPECT_EQ(detect_format("model.kmz", zip_head), InputFormat::Kmz);
}

TEST(OgrReader, ConnectionStringsAreToldFromFileNames) {
  EXPECT_TRUE(looks_like_connection_string("PG:dbname=city"));
  EXPECT_TRUE(looks_like_connection_string("WFS:https://example.org/wfs"));
  EXPECT_FALSE(looks_like_connection_string("C:\\data\\parts.shp"));
  EXPECT_FALSE(looks_like_connection_string("/vsizip/a.zip/parts.shp"));
  EXPECT_FALSE(looks_like_connection_string("parts.shp"));
  EXPECT_FALSE(looks_like_connection_string("dir/x:y.shp"));
}

TEST(OgrReader, MissingLayerOrFieldNamesTheSource) {
  const std::string path = "/vsimem/ogr_reader_test/m.geojson";
  put(path, kGeoJson);
  OgrInputOptions o;
  o.layers = {"nope"};
  try {
    read(path, o);
    ADD_FAILURE() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": has no layer 'nope'"), std::string::npos) << e.what();
  }
  o.layers.clear();
  o.id_field = "nope";
  EXPECT_THROW(read(path, o), InputError);
  o.id_field.clear();
  o.sql = "SELECT * FROM m";  // the GeoJSON layer is named after the file
  o.where = "name = 'square'";  // would be ignored: refused instead
  EXPECT_THROW(read(path, o), InputError);
  o.where.clear();
  EXPECT_EQ(read(path, o).meshes.size(), 4u);
  VSIUnlink(path.c_str());
}

}  // namespace
}  // namespace groundplan::gis

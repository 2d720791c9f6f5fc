// SPDX-License-Identifier: MIT
// The whole pipeline on real city models, checked against GEOS UnaryUnion through the C API
// (gis/geosref): same polygons and holes, symmetric difference <= 1e-9 of the area, all valid, and
// nothing lost (every building read is a footprint or a problem; every footprint is in a plan); no
// near-touching output vertices (tests/support/near_touch.h, issue 20).
#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/gis/pipeline.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "near_touch.h"
#include "test_support.h"

namespace groundplan {
namespace {

struct Case {
  const char* path;  // relative to sample_data/, or as in ../shared/data (test::shared_data)
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
  GROUNDPLAN_SKIP_IF_MISSING(options.inputs[0]);
  const gis::PipelineResult r = gis::run_pipeline(options);

  EXPECT_EQ(r.buildings_read, c.buildings);
  EXPECT_EQ(r.plans.size(), c.plans);
  std::size_t holes = 0;
  for (const auto& p : r.plans) holes += p.polygon.holes.size();
  EXPECT_EQ(holes, c.holes);
  EXPECT_FALSE(r.crs_wkt.empty());

  const gis::GeosComparison cmp = gis::compare_with_geos(r.footprints, r.plans);
  EXPECT_TRUE(cmp.matches(1e-9)) << cmp.summary();
  const testing::NearTouch nt = testing::near_touch(r.plans, 8, &r.footprints);
  EXPECT_EQ(nt.pairs, 0u) << nt.first;

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
                      Case{"tum-main-entrance/TUM-Main-Entrance.gml", false, 1, 1, 1}));
// Not redistributable (the third-party folder): skipped without it.
INSTANTIATE_TEST_SUITE_P(
    ThirdParty, PipelineOnRealData,
    ::testing::Values(Case{"citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml", true, 61, 18, 39}));

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
  EXPECT_EQ(testing::near_touch(r.plans, 8, &r.footprints).pairs, 0u) << testing::near_touch(r.plans).first;
}

// A folder: the first file is read alone (it fixes the working CRS), the others side by side, and their footprints
// are moved into the result side by side (pipeline.cpp append_footprints). They must come out file by file, in
// the folder's order, each file's as reading that file alone gives them.
TEST(Pipeline, FolderFootprintsComeOutFileByFileAsEachFileAlone) {
  namespace fs = std::filesystem;
  const fs::path folder = test::shared_data("citygml1-niedersachsen-lod1-4tiles");
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(folder))
    if (e.path().extension() == ".gml") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 4u);
  std::vector<Footprint> want;
  for (const std::string& f : files) {
    gis::PipelineOptions one;
    one.inputs = {f};
    one.threads = 1;
    gis::PipelineResult r = gis::run_pipeline(one);
    ASSERT_FALSE(r.footprints.empty()) << f;
    for (Footprint& fp : r.footprints) want.push_back(std::move(fp));
  }
  for (const int threads : {1, 3}) {
    gis::PipelineOptions options;
    options.inputs = {folder.string()};
    options.threads = threads;
    const gis::PipelineResult r = gis::run_pipeline(options);
    ASSERT_EQ(r.footprints.size(), want.size()) << threads << " threads";
    for (std::size_t i = 0; i < want.size(); ++i) {
      const Footprint &got = r.footprints[i], &w = want[i];
      ASSERT_EQ(got.source_file + " " + got.source_id, w.source_file + " " + w.source_id) << i << ", " << threads << " threads";
      ASSERT_EQ(got.polygons.size(), w.polygons.size()) << w.source_id;
      for (std::size_t k = 0; k < w.polygons.size(); ++k) ASSERT_EQ(got.polygons[k].outer, w.polygons[k].outer) << w.source_id;
    }
  }
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
// A folder of a file without CRS and a georeferenced one: whatever their order, the georeferenced file fixes the
// working CRS and the other is left out, its buildings and itself each a NO_CRS problem that names the file, the
// cause and -s_srs. (Before, the first file decided: the CRS-less file first made the georeferenced one fail.)
TEST(Pipeline, FileWithoutCrsIsNotMixedWithGeoreferencedFiles) {
  namespace fs = std::filesystem;
  struct Outcome {
    std::string crs;
    std::vector<std::string> footprints, no_crs;
  };
  auto run_with = [](const std::string& no_crs_name, const std::string& utm_name) {
    const fs::path dir = fs::temp_directory_path() / "groundplan_mixed_crs_test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(test::shared_data("citygml1-berlin-lod2-libcitygml/b1_lod2_s.gml"), dir / no_crs_name);
    fs::copy_file(test::sample_data("tum-main-entrance/TUM-Main-Entrance.gml"), dir / utm_name);
    gis::PipelineOptions options;
    options.inputs = {dir.string()};
    const gis::PipelineResult r = gis::run_pipeline(options);
    fs::remove_all(dir);
    Outcome o;
    o.crs = r.crs_name;
    for (const auto& f : r.footprints) {
      EXPECT_NE(f.source_file.find(utm_name), std::string::npos) << f.source_id;
      o.footprints.push_back(f.source_id);
    }
    bool file_problem = false;
    for (const auto& p : r.problems) {
      if (p.code != "NO_CRS") continue;
      EXPECT_NE(p.file.find(no_crs_name), std::string::npos) << p.reason;
      if (p.source_id.empty()) {
        file_problem = true;
        EXPECT_NE(p.reason.find(no_crs_name), std::string::npos) << p.reason;
        EXPECT_NE(p.reason.find("no srsName"), std::string::npos) << p.reason;
        EXPECT_NE(p.reason.find("-s_srs"), std::string::npos) << p.reason;
      } else {
        o.no_crs.push_back(p.source_id);
      }
      EXPECT_EQ(p.reason.find("target CRS"), std::string::npos) << p.reason;
    }
    EXPECT_TRUE(file_problem) << "no problem names the file without CRS";
    EXPECT_EQ(r.buildings_read, r.footprints.size() + r.buildings_dropped);
    std::sort(o.footprints.begin(), o.footprints.end());
    std::sort(o.no_crs.begin(), o.no_crs.end());
    return o;
  };
  const Outcome first = run_with("a_no_crs.gml", "b_utm32.gml");  // the file without CRS read first
  const Outcome last = run_with("b_no_crs.gml", "a_utm32.gml");   // ... and last
  EXPECT_EQ(first.crs, "EPSG:25832");
  EXPECT_EQ(last.crs, first.crs);
  ASSERT_FALSE(first.footprints.empty());
  EXPECT_EQ(last.footprints, first.footprints);
  ASSERT_FALSE(first.no_crs.empty());
  EXPECT_EQ(last.no_crs, first.no_crs);
}

}  // namespace
}  // namespace groundplan

namespace groundplan {
namespace {

TEST(PipelineThirdParty, AxisOrderOptionPlacesALonLatFileWhereItIs) {
  // The OGC Jefferson Building sample says "EPSG:4979" (EPSG's order: lat, lon) and writes lon, lat. GDAL's
  // GML convention reads the short form "EPSG:n" longitude first, so as written it lands in Washington DC,
  // as with --axis-order east-north; --axis-order north-east reads it latitude first, at "latitude -77"
  // (UTM of the far south). Before that convention (issue 16), as written was the latter.
  gis::PipelineOptions options;
  options.inputs = {test::shared_data(
      "citygml-ogc-spec-samples/JeffersonBuilding_CityGML3.0_LOD1_with_xAL3_CommonTypes.gml")};
  GROUNDPLAN_SKIP_IF_MISSING(options.inputs[0]);
  const gis::PipelineResult as_written = gis::run_pipeline(options);
  options.source_axis = gis::axis_order_from_string("north-east");
  const gis::PipelineResult lat_first = gis::run_pipeline(options);
  options.source_axis = gis::axis_order_from_string("east-north");
  const gis::PipelineResult swapped = gis::run_pipeline(options);
  ASSERT_EQ(swapped.plans.size(), 1u);
  EXPECT_EQ(swapped.crs_name, "EPSG:32618");  // UTM 18N
  EXPECT_EQ(as_written.crs_name, swapped.crs_name);
  EXPECT_EQ(test::plan_keys(as_written.plans), test::plan_keys(swapped.plans));
  EXPECT_NE(lat_first.crs_name, swapped.crs_name);
  const Point2 p = swapped.plans[0].polygon.outer[0];
  EXPECT_NEAR(p.x, 325700, 1000);
  EXPECT_NEAR(p.y, 4306600, 1000);
  EXPECT_GT(swapped.plans[0].area_m2, 100);  // a building, not a degenerate sliver
  EXPECT_THROW(gis::axis_order_from_string("sideways"), InvalidArgument);
}

}  // namespace
}  // namespace groundplan

namespace groundplan {
namespace {

// Footprints are made on other cores while the file is read on; the result must not show it: the
// footprints in reading order, and each footprint problem where it stands in reading order among
// the reader's own problems, exactly as when they were made one by one.
TEST(Pipeline, FootprintsMadeInParallelComeOutInReadingOrder) {
  namespace fs = std::filesystem;
  auto ring = [](double x0, double y0, double x1, double y1, double z0, double z1, int side) {
    // side 0: floor, 1: roof, 2..5: walls of the box [x0,x1]x[y0,y1]x[z0,z1]
    char buf[512];
    switch (side) {
      case 0: std::snprintf(buf, sizeof buf, "%.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f", x0, y0, z0, x0, y1, z0, x1, y1, z0, x1, y0, z0, x0, y0, z0); break;
      case 1: std::snprintf(buf, sizeof buf, "%.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f", x0, y0, z1, x1, y0, z1, x1, y1, z1, x0, y1, z1, x0, y0, z1); break;
      case 2: std::snprintf(buf, sizeof buf, "%.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f", x0, y0, z0, x1, y0, z0, x1, y0, z1, x0, y0, z1, x0, y0, z0); break;
      case 3: std::snprintf(buf, sizeof buf, "%.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f", x1, y0, z0, x1, y1, z0, x1, y1, z1, x1, y0, z1, x1, y0, z0); break;
      case 4: std::snprintf(buf, sizeof buf, "%.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f", x1, y1, z0, x0, y1, z0, x0, y1, z1, x1, y1, z1, x1, y1, z0); break;
      default: std::snprintf(buf, sizeof buf, "%.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f %.1f", x0, y1, z0, x0, y0, z0, x0, y0, z1, x0, y1, z1, x0, y1, z0); break;
    }
    return "<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">" +
           std::string(buf) + "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>\n";
  };
  // Building i: i % 3 == 0 a box; 1 two parallel walls only (no footprint: a problem of stage
  // "footprint"); 2 a box with a two-point ring too (a problem of stage "read", footprint made).
  const int n = 600;
  std::string gml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\" "
      "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" xmlns:gml=\"http://www.opengis.net/gml\">\n"
      "<gml:boundedBy><gml:Envelope srsName=\"EPSG:25832\" srsDimension=\"3\"><gml:lowerCorner>400000 5860000 40"
      "</gml:lowerCorner><gml:upperCorner>412000 5860100 48</gml:upperCorner></gml:Envelope></gml:boundedBy>\n";
  for (int i = 0; i < n; ++i) {
    const double x0 = 400000.0 + 20.0 * i, y0 = 5860000.0, x1 = x0 + 10, y1 = y0 + 8;
    gml += "<core:cityObjectMember><bldg:Building gml:id=\"B" + std::to_string(i) +
           "\"><bldg:lod1Solid><gml:Solid><gml:exterior><gml:CompositeSurface>\n";
    if (i % 3 == 1) {
      gml += ring(x0, y0, x1, y1, 40, 48, 2) + ring(x0, y0, x1, y1, 40, 48, 4);
    } else {
      for (int side = 0; side < 6; ++side) gml += ring(x0, y0, x1, y1, 40, 48, side);
      if (i % 3 == 2)
        gml += "<gml:surfaceMember><gml:Polygon gml:id=\"P" + std::to_string(i) +  // an id: not named by its line,
               "\"><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">" +  // so chunks may read it
               std::to_string(x0) + " 5860000 48 " + std::to_string(x1) + " 5860000 48 " + std::to_string(x0) +
               " 5860000 48</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>\n";
    }
    gml += "</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod1Solid></bldg:Building></core:cityObjectMember>\n";
  }
  gml += "</core:CityModel>\n";
  const fs::path file = fs::temp_directory_path() / "groundplan_parallel_footprints_test.gml";
  {
    std::FILE* f = std::fopen(file.string().c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fwrite(gml.data(), 1, gml.size(), f);
    std::fclose(f);
  }
  // Read whole, and in chunks of 64 KiB side by side (their parts appended in parallel, file_reading.cpp).
  for (const std::int64_t chunk : {std::int64_t{0}, std::int64_t{1} << 16}) {
    SCOPED_TRACE("read_chunk_bytes " + std::to_string(chunk));
    gis::PipelineOptions options;
    options.inputs = {file.string()};
    options.read_chunk_bytes = chunk;
    options.threads = 2;
    const gis::PipelineResult r = gis::run_pipeline(options);
    EXPECT_EQ(r.reading.chunks, chunk ? 15u : 0u) << (r.reading.read_whole.empty() ? std::string() : r.reading.read_whole[0].second);

    std::vector<std::string> want_fp;
    for (int i = 0; i < n; ++i)
      if (i % 3 != 1) want_fp.push_back("B" + std::to_string(i));
    std::vector<std::string> got_fp;
    for (const Footprint& f : r.footprints) {
      got_fp.push_back(f.source_id);
      EXPECT_EQ(f.source_file, file.string()) << f.source_id;
      EXPECT_EQ(f.method, "solid-bottom") << f.source_id;  // lod1Solid boxes
    }
    EXPECT_EQ(got_fp, want_fp);

    // Problems naming buildings, in order: B1 (footprint), B2 (read), B4 (footprint), B5 (read), ...
    std::vector<std::string> want_pb, got_pb;
    for (int i = 0; i < n; ++i)
      if (i % 3 != 0) want_pb.push_back("B" + std::to_string(i) + (i % 3 == 1 ? " footprint" : " read"));
    for (const Problem& p : r.problems)
      if (!p.source_id.empty()) got_pb.push_back(p.source_id + " " + p.stage);
    EXPECT_EQ(got_pb, want_pb);
    EXPECT_EQ(r.buildings_read, static_cast<std::size_t>(n));
    EXPECT_EQ(r.buildings_dropped, static_cast<std::size_t>(n / 3));
  }
  fs::remove(file);
}

// A folder's own files are its inputs (a zip's entries at any depth are): one that holds none says which of its
// subfolders hold some (kml-collada-korea-mago/ is such a folder: its KMLs are in sample-kml/ and
// sample-kml-error-case/), and a folder with none anywhere says only what a folder may hold.
/// The message of the InputError that run_pipeline throws on `options` (a failure when none is thrown).
std::string input_error(const gis::PipelineOptions& options) {
  try {
    (void)gis::run_pipeline(options);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(Pipeline, FolderWithoutInputFilesNamesTheSubfoldersThatHaveSome) {
  const test::TempDir dir;
  dir.file("a/one.gml", "<x/>");
  dir.file("b/c/two.kml", "<x/>");
  dir.file("b/c/model.dae", "<x/>");  // a KML's model, not an input
  dir.file("d/notes.txt", "not an input");
  dir.file("readme.txt", "not an input");
  gis::PipelineOptions options;
  options.inputs = {dir.path.string()};
  std::string m = input_error(options);
  EXPECT_NE(m.find("folder holds no input file"), std::string::npos) << m;
  EXPECT_NE(m.find("subfolders are not read, and these hold input files: a/ b/c/ (name one"), std::string::npos) << m;
  EXPECT_EQ(m.find("d/"), std::string::npos) << m;
  std::filesystem::remove_all(dir.path / "a");
  std::filesystem::remove_all(dir.path / "b");
  m = input_error(options);
  EXPECT_NE(m.find("folder holds no input file"), std::string::npos) << m;
  EXPECT_EQ(m.find("subfolders"), std::string::npos) << m;
}

// The CLI's source and what follows GROUNDPLAN: name one input or several separated by commas; a path that
// exists as written is one input, commas and all.
TEST(Pipeline, InputListSplitsAtCommasUnlessThePathExists) {
  EXPECT_EQ(gis::input_list("tiles/a.gml"), (std::vector<std::string>{"tiles/a.gml"}));
  EXPECT_EQ(gis::input_list("a.gml,b/,,c.kmz"), (std::vector<std::string>{"a.gml", "b/", "c.kmz"}));
  EXPECT_EQ(gis::input_list("\"x,1.gml\",y.gml"), (std::vector<std::string>{"x,1.gml", "y.gml"}));
  const test::TempDir dir;
  const std::string odd = dir.file("tile,1.gml", "<x/>");
  EXPECT_EQ(gis::input_list(odd), (std::vector<std::string>{odd}));
  // Two folders by commas read as one input: the Niedersachsen tiles split in two folders give all 4 tiles' plans.
  const std::filesystem::path tiles = test::shared_data("citygml1-niedersachsen-lod1-4tiles");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(tiles))
    if (e.path().extension() == ".gml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 4u);
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::filesystem::path to = dir.path / (i < 2 ? "first" : "second") / files[i].filename();
    std::filesystem::create_directories(to.parent_path());
    std::filesystem::copy_file(files[i], to);
  }
  gis::PipelineOptions split, whole;
  split.inputs = gis::input_list((dir.path / "first").string() + "," + (dir.path / "second").string());
  whole.inputs = {tiles.string()};
  const gis::PipelineResult a = gis::run_pipeline(split), b = gis::run_pipeline(whole);
  EXPECT_EQ(a.buildings_read, b.buildings_read);
  EXPECT_EQ(test::plan_keys(a.plans), test::plan_keys(b.plans));
  EXPECT_FALSE(a.plans.empty());
}

}  // namespace
}  // namespace groundplan

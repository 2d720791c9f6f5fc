// SPDX-License-Identifier: MIT
// Compressed inputs (issue 16): x.gml.gz, x.city.json.gz, x.city.jsonl.gz are found by name, read through
// GDAL's /vsigzip/ and give what the plain file gives; a gzip bomb stops at gzip_max_ratio with an error
// naming the file instead of filling memory.
#include <groundplan/error.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/reader.h>

#include <cpl_vsi.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>
#include <vector>

#include "read_all.h"
#include "test_support.h"

namespace groundplan {
namespace {

/// Writes `text` gzip-compressed to `path` (GDAL writes /vsigzip/ too).
void write_gz(const std::string& path, const std::string& text) {
  VSILFILE* f = VSIFOpenL(("/vsigzip/" + path).c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  ASSERT_EQ(VSIFWriteL(text.data(), 1, text.size(), f), text.size());
  VSIFCloseL(f);
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

gis::PipelineResult run(const std::string& input) {
  gis::PipelineOptions o;
  o.inputs = {input};
  return gis::run_pipeline(o);
}

TEST(CompressedInput, NamesAndFormats) {
  for (const char* name : {"a.gml.gz", "a.GML.GZ", "a.city.json.gz", "a.city.jsonl.gz", "a.kml.gz", "a.xml.gz"}) {
    EXPECT_TRUE(gis::is_gzip_input_name(name)) << name;
    EXPECT_TRUE(gis::is_input_name(name)) << name;
  }
  for (const char* name : {"a.gz", "a.tar.gz", "a.json.gz", "a.gml"}) EXPECT_FALSE(gis::is_gzip_input_name(name)) << name;
  // The messages that say what a folder or zip may hold name exactly what is taken.
  const std::string patterns = gis::input_name_patterns();
  for (const std::string name : {"x.gml", "x.citygml", "x.xml", "x.kml", "x.kmz", "x.gltf", "x.glb", "x.city.json",
                                 "x.city.jsonl", "x.gml.gz", "x.kml.gz", "x.city.json.gz", "x.city.jsonl.gz"}) {
    EXPECT_TRUE(gis::is_input_name(name)) << name;
    EXPECT_NE(patterns.find("*" + name.substr(1)), std::string::npos) << name << " not in " << patterns;
  }
  for (const char* name : {"x.dae", "tileset.json", "x.kmz.gz", "x.txt"}) EXPECT_FALSE(gis::is_input_name(name)) << name;
  EXPECT_EQ(gis::detect_format("x.city.json.gz", ""), gis::InputFormat::CityJson);
  EXPECT_EQ(gis::detect_format("x.city.jsonl.gz", ""), gis::InputFormat::CityJsonSeq);
  EXPECT_EQ(gis::detect_format("x.gml.gz", ""), gis::InputFormat::CityGml);
  EXPECT_EQ(gis::open_path("/d/x.gml.gz"), "/vsigzip//d/x.gml.gz");
  EXPECT_EQ(gis::open_path("/vsigzip//d/x.gml.gz"), "/vsigzip//d/x.gml.gz");
  EXPECT_EQ(gis::open_path("/d/x.gml"), "/d/x.gml");
}

// Real samples, gzipped into a temporary folder: the same plans, footprints and CRS as the plain file,
// alone and as a folder of tiles.
void expect_gzipped_gives_plain(const test::TempDir& dir, const std::vector<std::string>& samples) {
  for (const std::string& rel : samples) {
    const std::string plain = test::shared_data(rel);
    const bool bag = rel.find("3dbag") != std::string::npos;  // one CRS to a folder
    std::filesystem::create_directories(dir.path / (bag ? "bag" : "gml"));
    const std::string gz = (dir.path / (bag ? "bag" : "gml") / (rel.substr(rel.find('/') + 1) + ".gz")).string();
    write_gz(gz, slurp(plain));
    const gis::PipelineResult a = run(plain), b = run(gz);
    ASSERT_FALSE(a.plans.empty()) << rel;
    EXPECT_EQ(test::plan_keys(a.plans), test::plan_keys(b.plans)) << rel;
    EXPECT_EQ(a.buildings_read, b.buildings_read) << rel;
    EXPECT_EQ(a.footprints.size(), b.footprints.size()) << rel;
    EXPECT_EQ(a.crs_name, b.crs_name) << rel;
    EXPECT_EQ(a.problems.size(), b.problems.size()) << rel;
  }
}

/// Nothing is written beside the inputs (GDAL's x.gz.properties cache is off while reading them).
void expect_no_properties_files(const test::TempDir& dir) {
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path))
    EXPECT_NE(e.path().extension(), ".properties") << e.path();
}

TEST(CompressedInput, RealSamplesGiveWhatThePlainFileGives) {
  const test::TempDir dir("groundplan_gz_test");
  expect_gzipped_gives_plain(dir, {"cityjson-3dbag-cjseq/3dbag_b2.city.json", "cityjson-3dbag-cjseq/3dbag_b2.city.jsonl",
                                   "citygml-fzkhaus-denhaag-misc/TUM-Main-Entrance.gml"});
  expect_no_properties_files(dir);
  // A folder of tiles: its .gz files found by name.
  EXPECT_EQ(run((dir.path / "bag").string()).buildings_read, 2 * run(test::shared_data("cityjson-3dbag-cjseq/3dbag_b2.city.json")).buildings_read);
}

TEST(CompressedInputThirdParty, RealSamplesGiveWhatThePlainFileGives) {
  GROUNDPLAN_SKIP_IF_MISSING(test::shared_data("kml-collada-korea-mago/sample-kml/a_bd001.kml"));
  const test::TempDir dir("groundplan_gz_test");
  expect_gzipped_gives_plain(dir, {"citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml",
                                   "citygml-ogc-spec-samples/v2_Building_and_garage_LOD2-EPSG25832.gml"});
  // A KML whose COLLADA model lies beside it: the model is found beside the .kml.gz, not inside /vsigzip/.
  std::filesystem::create_directories(dir.path / "kml");
  const std::string kml = test::shared_data("kml-collada-korea-mago/sample-kml/a_bd001.kml");
  std::filesystem::copy_file(test::shared_data("kml-collada-korea-mago/sample-kml/a_bd001.dae"), dir.path / "kml" / "a_bd001.dae");
  write_gz((dir.path / "kml" / "a_bd001.kml.gz").string(), slurp(kml));
  const gis::PipelineResult k = run(kml), kgz = run((dir.path / "kml" / "a_bd001.kml.gz").string());
  ASSERT_EQ(k.footprints.size(), 1u);
  EXPECT_EQ(test::plan_keys(k.plans), test::plan_keys(kgz.plans));
  EXPECT_EQ(kgz.problems.size(), k.problems.size());
  expect_no_properties_files(dir);
}

// A gzip bomb: 16 MB of blanks inside valid documents pack to ~16 KB; with the ratio at 100 and the floor
// at 1 MiB, reading stops after ~1.6 MB with an InputError naming the file.
TEST(CompressedInput, GzipBombStopsAtTheRatio) {
  const test::TempDir dir("groundplan_gz_test");
  const std::string blanks(16u << 20, ' ');
  const std::string json = std::string(R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[])") + blanks + "}";
  const std::string seq = std::string(R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[]})") + "\n" + blanks + "\n";
  const std::string gml = "<?xml version=\"1.0\"?>\n<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\">" +
                          blanks + "</core:CityModel>\n";
  gis::ReadOptions opt;
  opt.gzip_min_bytes = 1 << 20;
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"bomb.city.json.gz", json}, {"bomb.city.jsonl.gz", seq}, {"bomb.gml.gz", gml}}) {
    const std::string path = (dir.path / name).string();
    write_gz(path, text);
    try {
      test::read(path, opt);
      ADD_FAILURE() << name << ": read to the end";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find("gzip bomb"), std::string::npos) << what;
    }
    opt.gzip_max_ratio = 100000;  // the same file read whole when the limit allows it
    EXPECT_NO_THROW(test::read(path, opt)) << name;
    opt.gzip_max_ratio = 100;
  }
}

// -progress for a .gz moves with its packed bytes (the progress total counts file sizes on disk): read_any
// tells ReadOptions::on_bytes packed bytes while it reads, ending exactly at the packed size; a plain file
// gets its own bytes, also while it is read, not in one lump at the end.
TEST(CompressedInput, ProgressCountsPackedBytesWhileReading) {
  const test::TempDir dir("groundplan_gz_test");
  // ~3.5 MB of text each that packs a few times (digits from an LCG), so reading takes several chunks.
  std::uint64_t x = 12345;
  auto digits = [&] {
    x = x * 6364136223846793005ull + 1442695040888963407ull;
    return std::to_string(x >> 20);
  };
  std::string json = R"({"type":"CityJSON","version":"2.0","CityObjects":{)";
  std::string seq = R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[]})" "\n";
  std::string gml = "<?xml version=\"1.0\"?>\n<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\">\n";
  for (int i = 0; i < 60000; ++i) {
    const std::string d = digits();
    json += (i ? ",\"b" : "\"b") + std::to_string(i) + R"(":{"type":"GenericCityObject","attributes":{"n":")" + d + "\"}}";
    seq += R"({"type":"CityJSONFeature","id":"f)" + std::to_string(i) + R"(","CityObjects":{},"vertices":[],"n":")" + d + "\"}\n";
    gml += "<!-- " + d + " " + d + " " + d + " " + std::to_string(i) + " -->\n";
  }
  json += R"(},"vertices":[]})";
  gml += "</core:CityModel>\n";
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"p.city.json", json}, {"p.city.jsonl", seq}, {"p.gml", gml}}) {
    ASSERT_GT(text.size(), 3u << 20) << name;
    const std::string plain = (dir.path / name).string(), gz = plain + ".gz";
    std::ofstream(plain, std::ios::binary) << text;
    write_gz(gz, text);
    for (const std::string& path : {plain, gz}) {
      const std::uint64_t size = std::filesystem::file_size(path);
      std::vector<std::uint64_t> told;
      gis::ReadOptions opt;
      opt.on_bytes = [&](std::uint64_t n) { told.push_back(n); };
      test::read(path, opt);
      std::uint64_t sum = 0;
      for (std::uint64_t n : told) {
        EXPECT_GT(n, 0u) << path;
        sum += n;
      }
      EXPECT_EQ(sum, size) << path;                        // exactly the file's bytes on disk
      ASSERT_GE(told.size(), 3u) << path;                  // told while reading, not once at the end
      EXPECT_LT(told.front(), size / 2) << path;           // the first report is not most of the file
      if (path == gz) EXPECT_LT(size, text.size() / 2) << path;  // packed: a count of unpacked bytes would overshoot
    }
  }
}

}  // namespace
}  // namespace groundplan

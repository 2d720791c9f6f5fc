// SPDX-License-Identifier: MIT
// What the footprint check (core/src/footprint/ground_check.h) costs against reading: per file, the median
// time to read every building (read_any) and make its footprint by decomposition (`--footprints decompose`,
// which ignores semantics and runs the check; the solids keep their bottoms, so the check has lowest faces to
// test), and the median time of the check alone on the same meshes and footprints; printed with their ratio
// (goal: at most 5 %). One thread. Not a test.
//   ground_check_bench [file ...]   (default: the CityGML samples under sample_data/ and two shared ones)
#include "footprint/ground_check.h"

#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/reader.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "test_config.h"
#include "test_support.h"

namespace {

using namespace groundplan;

std::vector<Mesh> read_meshes(const std::string& path) {
  std::vector<Problem> problems;
  gis::ReadInfo info;
  std::vector<Mesh> meshes;
  gis::read_any(path, {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
  // Into metres as the pipeline does (CityGML in degrees: the working UTM zone); KML, COLLADA and glTF
  // arrive placed.
  std::unique_ptr<gis::WorkingFrame> frame;
  if (!info.in_working_crs) try {
      frame = std::make_unique<gis::WorkingFrame>(info.citygml.srs_name, gis::CrsOptions{}, path);
    } catch (const std::exception&) {
    }
  if (frame && !frame->identity()) {
    std::vector<Mesh> placed;
    for (Mesh& m : meshes)
      if (frame->transform(m)) placed.push_back(std::move(m));
    meshes.swap(placed);
  }
  return meshes;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) files.push_back(argv[i]);
  if (files.empty()) {
    for (const char* f : {"plateau-niiza/53392547_bldg_6697_op2.gml", "plateau-niiza/53395404_bldg_6697_op.gml",
                          "niedersachsen-lorup/LoD1_24065862_2_2021-01-25.gml", "tum-main-entrance/TUM-Main-Entrance.gml"})
      files.push_back(std::string(GROUNDPLAN_SAMPLE_DATA_DIR) + "/" + f);
    for (const char* f : {"citygml1-berlin-lod2-libcitygml", "kml-collada-macky-google/model-macky.kmz"}) {
      const std::string p = test::shared_data(f);
      if (std::filesystem::is_regular_file(p)) files.push_back(p);
      else if (std::filesystem::is_directory(p))
        for (const auto& e : std::filesystem::directory_iterator(p))
          if (e.path().extension() == ".gml") {
            files.push_back(e.path().string());
            break;
          }
    }
  }
  FootprintParams params;
  params.source = FootprintSource::Decompose;
  std::printf("%-40s %9s %9s %10s %10s %7s\n", "file", "buildings", "footprints", "read_s", "check_s", "ratio");
  for (const std::string& path : files) {
    std::vector<Mesh> meshes;
    std::vector<FootprintResult> fps;
    std::size_t flagged = 0, ok = 0;
    const double read_s = bench::median_seconds([&] {
      meshes = read_meshes(path);
      fps.clear();
      for (const Mesh& m : meshes) fps.push_back(make_footprint(m, params));
    });
    for (const FootprintResult& f : fps) flagged += !f.misses_ground.empty(), ok += f.ok;
    double sink = 0;
    const double check_s = bench::median_seconds([&] {
      for (std::size_t i = 0; i < meshes.size(); ++i)
        if (fps[i].ok) sink += footprint::check_ground(meshes[i], fps[i].footprint.polygons, params).uncovered_m2;
    });
    std::printf("%-40s %9zu %9zu %10.4f %10.6f %6.2f%%%s\n", std::filesystem::path(path).filename().string().c_str(),
                meshes.size(), ok, read_s, check_s, 100 * check_s / read_s,
                flagged ? (" (" + std::to_string(flagged) + " footprints miss ground)").c_str() : "");
    if (sink < 0) std::puts("");
  }
  return 0;
}

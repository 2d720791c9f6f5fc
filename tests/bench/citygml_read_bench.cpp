// SPDX-License-Identifier: MIT
// MB/s of CityGML into meshes (issue 6 goal: >= 100 MB/s per core), on one core, with expat's bare
// parse of the same bytes as the yardstick. Usage: citygml_read_bench [file ...] (default: the largest
// real samples under GROUNDPLAN_SHARED_DATA_DIR). The file is read into memory once so that the
// figure is the parser's, not the disk's.
#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>

#include <expat.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_config.h"

namespace {

using Clock = std::chrono::steady_clock;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

template <class F>
double best_seconds(F&& f, double budget_s = 2.0) {
  double best = 1e300, spent = 0;
  int runs = 0;
  while (spent < budget_s || runs < 3) {
    auto t0 = Clock::now();
    f();
    double s = std::chrono::duration<double>(Clock::now() - t0).count();
    best = std::min(best, s);
    spent += s;
    ++runs;
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) files.push_back(argv[i]);
  if (files.empty()) {
    const std::string d = GROUNDPLAN_SHARED_DATA_DIR;
    files = {d + "/citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml",
             d + "/citygml1-niedersachsen-lod1-4tiles/LoD1_24085862_2_2021-01-25.gml",
             d + "/citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml",
             d + "/citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml",
             d + "/citygml-citygml4j-samples/lod3_building_v2.gml"};
  }
  std::printf("%-48s %8s %7s %10s %10s %12s\n", "file", "MB", "meshes", "expat MB/s", "read MB/s", "+fp MB/s");
  for (const std::string& path : files) {
    const std::string xml = slurp(path);
    const double mb = xml.size() / 1e6;
    // Yardstick: expat in namespace mode with no handlers.
    double bare = best_seconds([&] {
      XML_Parser p = XML_ParserCreateNS(nullptr, ' ');
      XML_Parse(p, xml.data(), static_cast<int>(xml.size()), XML_TRUE);
      XML_ParserFree(p);
    });
    std::size_t meshes = 0;
    double read = best_seconds([&] {
      std::vector<groundplan::Problem> problems;
      groundplan::gis::SourceInfo info;
      meshes = 0;
      groundplan::gis::CityGmlOptions o; if (std::getenv("NOINDEX")) o.xlink_index_max_vertices = 0;
      groundplan::gis::read_citygml_buffer(xml, path, o, [&](groundplan::Mesh&&) { ++meshes; }, problems, info);
    });
    // Read + working frame + explicit footprint: what the pipeline does per building before the union.
    double with_fp = best_seconds([&] {
      std::vector<groundplan::Problem> problems;
      groundplan::gis::SourceInfo info;
      std::unique_ptr<groundplan::gis::WorkingFrame> frame;
      groundplan::gis::read_citygml_buffer(
          xml, path, {},
          [&](groundplan::Mesh&& m) {
            if (!frame) frame = std::make_unique<groundplan::gis::WorkingFrame>(info.srs_name);
            frame->transform(m);
            groundplan::FootprintResult r = groundplan::make_footprint(m);
            (void)r;
          },
          problems, info);
    });
    std::string name = path.substr(path.find_last_of('/') + 1);
    if (name.size() > 48) name = name.substr(0, 45) + "...";
    std::printf("%-48s %8.2f %7zu %10.1f %10.1f %12.1f\n", name.c_str(), mb, meshes, mb / bare, mb / read,
                mb / with_fp);
  }
  return 0;
}

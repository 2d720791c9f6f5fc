// SPDX-License-Identifier: MIT
// MB/s of CityGML into meshes on one core (issue 6: >= 100 MB/s; issue 14: >= 150 MB/s), against
// the parsers on the same bytes as yardsticks: expat bare (no handlers: expat then skips building the
// element names and attribute arrays), expat with empty element handlers in namespace mode (the least
// any expat-based reader pays), and pugixml's parse alone with the reader's flags (the floor of the
// in-memory path, gis/src/xml/dom_events.h). The reader is timed both ways: in memory (the default,
// "read") and streamed through expat (dom_max_bytes = 0, "read/x"). Figures are medians of the
// thread's CPU time (the machine may be loaded), each file read into memory once so that the figure is
// the parser's, not the disk's.
//
// Usage: citygml_read_bench [--runs N] [--only expat|handlers|pugixml|read|streamed|fp] [file ...]
//   (default files: the largest real samples under GROUNDPLAN_SHARED_DATA_DIR; --only runs that one
//   measurement N times, for `perf record`).
#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>

#include <expat.h>
#include <pugixml.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "test_config.h"

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string s(static_cast<std::size_t>(std::max<std::streamoff>(0, in.tellg())), '\0');
  in.seekg(0);
  in.read(s.data(), static_cast<std::streamsize>(s.size()));
  return s;
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

/// Median CPU seconds of `runs` calls (a small file is repeated until a call takes >= 20 ms).
template <class F>
double median_cpu_seconds(F&& f, int runs, std::size_t bytes) {
  const int reps = bytes >= (8u << 20) ? 1 : static_cast<int>(std::max<std::size_t>(1, (8u << 20) / std::max<std::size_t>(bytes, 1)));
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    const double t0 = thread_cpu_seconds();
    for (int k = 0; k < reps; ++k) f();
    t.push_back((thread_cpu_seconds() - t0) / reps);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

void XMLCALL empty_start(void*, const XML_Char*, const XML_Char**) {}
void XMLCALL empty_end(void*, const XML_Char*) {}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  int runs = 5;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else files.push_back(argv[i]);
  }
  if (files.empty()) {
    const std::string d = GROUNDPLAN_SHARED_DATA_DIR;
    files = {d + "/citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml",
             d + "/citygml1-niedersachsen-lod1-4tiles/LoD1_24085862_2_2021-01-25.gml",
             d + "/citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml",
             d + "/citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml",
             d + "/citygml-citygml4j-samples/lod3_building_v2.gml"};
  }
  const bool all = only.empty();
  std::printf("CPU-time medians of %d runs\n", runs);
  std::printf("%-44s %7s %6s %9s %9s %9s %9s %9s %9s %6s\n", "file", "MB", "meshes", "expat", "expat+h", "pugixml",
              "read/x", "read", "read+fp", "read/x");
  for (const std::string& path : files) {
    const std::string xml = slurp(path);
    const double mb = static_cast<double>(xml.size()) / 1e6;
    auto bare_expat = [&](bool handlers) {
      XML_Parser p = XML_ParserCreateNS(nullptr, ' ');
      if (handlers) XML_SetElementHandler(p, empty_start, empty_end);
      // In 1 MiB pieces, as the reader feeds it (one XML_Parse of a whole 150 MB buffer is slower).
      constexpr std::size_t kPiece = 1 << 20;
      for (std::size_t off = 0; off < xml.size(); off += kPiece)
        XML_Parse(p, xml.data() + off, static_cast<int>(std::min(kPiece, xml.size() - off)), XML_FALSE);
      XML_Parse(p, nullptr, 0, XML_TRUE);
      XML_ParserFree(p);
    };
    double bare = 0, handlers = 0, pugi_alone = 0, streamed = 0, read = 0, with_fp = 0;
    if (all || only == "expat") bare = median_cpu_seconds([&] { bare_expat(false); }, runs, xml.size());
    if (all || only == "handlers") handlers = median_cpu_seconds([&] { bare_expat(true); }, runs, xml.size());
    if (all || only == "pugixml")
      pugi_alone = median_cpu_seconds(
          [&] {
            pugi::xml_document doc;
            doc.load_buffer(xml.data(), xml.size(), pugi::parse_default | pugi::parse_ws_pcdata_single,
                            pugi::encoding_utf8);
          },
          runs, xml.size());
    std::size_t meshes = 0;
    std::string streamed_why;
    auto reader = [&](std::size_t in_memory, double& seconds) {
      seconds = median_cpu_seconds(
          [&] {
            std::vector<groundplan::Problem> problems;
            groundplan::gis::SourceInfo info;
            meshes = 0;
            groundplan::gis::CityGmlOptions o;
            o.dom_max_bytes = in_memory;
            groundplan::gis::read_citygml_buffer(xml, path, o, [&](groundplan::Mesh&&) { ++meshes; }, problems, info);
            if (in_memory) streamed_why = info.streamed_why;
          },
          runs, xml.size());
    };
    if (all || only == "streamed") reader(0, streamed);
    if (all || only == "read") reader(std::max<std::size_t>(xml.size(), groundplan::gis::CityGmlOptions{}.dom_max_bytes), read);
    // Read + working frame + explicit footprint: what the pipeline does per building before the union.
    if (all || only == "fp")
      with_fp = median_cpu_seconds(
          [&] {
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
          },
          runs, xml.size());
    std::string name = path.substr(path.find_last_of('/') + 1);
    if (name.size() > 44) name = name.substr(0, 41) + "...";
    auto rate = [&](double s) { return s > 0 ? mb / s : 0.0; };
    std::printf("%-44s %7.2f %6zu %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %5.2fx\n", name.c_str(), mb, meshes, rate(bare),
                rate(handlers), rate(pugi_alone), rate(streamed), rate(read), rate(with_fp),
                read > 0 && streamed > 0 ? streamed / read : 0.0);
    if (!streamed_why.empty()) std::printf("  (not read in memory: %s)\n", streamed_why.c_str());
  }
  std::printf("(MB/s of CPU time; expat = no handlers, expat+h = empty start/end handlers in namespace mode; pugixml =\n"
              " its parse alone; read/x = the reader streamed through expat, read = in memory (the default);\n"
              " last column: in memory against streamed, the speed-up)\n");
  return 0;
}

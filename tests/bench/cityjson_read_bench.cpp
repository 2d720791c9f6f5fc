// SPDX-License-Identifier: MIT
// CityJSON reading speed (issue 16): MB/s per core of gis::read_any (file -> meshes) against the JSON
// parser alone on the same bytes: simdjson's DOM (runtime-dispatched kernel) and a full On-Demand walk
// touching every number (the kernel compiled into our reader); for a .city.jsonl, simdjson's parse_many over
// its lines. One thread, medians of N runs of the thread's CPU time (wall time beside read_any's line).
// Usage: cityjson_read_bench FILE [runs=5]
//        cityjson_read_bench --generate N DIR [runs=5]  (3DBAG-like: N buildings, BuildingPart with a
//        lod "2.2" Solid of 12 faces with semantics, integer vertices + transform; writes DIR/gen.city.json
//        and DIR/gen.city.jsonl, then measures both)
#include <groundplan/gis/reader.h>

#include <nlohmann/json.hpp>
#include <simdjson.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <time.h>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

/// nlohmann-json's SAX with a handler that only counts: the cost of the parse alone.
struct CountingSax : nlohmann::json_sax<nlohmann::json> {
  std::size_t numbers = 0;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return ++numbers, true; }
  bool number_unsigned(number_unsigned_t) override { return ++numbers, true; }
  bool number_float(number_float_t, const string_t&) override { return ++numbers, true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }
};

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// CPU time of this thread, the median of the runs (on a loaded machine the CPU time is the figure to
/// compare: wall time there counts the waits for a core). `wall` gets the median wall time.
double median_seconds(int runs, const std::function<void()>& f, double* wall = nullptr) {
  std::vector<double> s, w;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_seconds();
    f();
    s.push_back(thread_cpu_seconds() - c0);
    w.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(s.begin(), s.end());
  std::sort(w.begin(), w.end());
  if (wall) *wall = w[w.size() / 2];
  return s[s.size() / 2];
}

// A building with a roof ridge: 10 vertices, ground, 2 roof planes, 4 walls (2 of them 5-gons).
std::string building_objects(std::size_t i, std::size_t& v0, std::string& vertices) {
  const long x = static_cast<long>(i % 1000) * 20000, y = static_cast<long>(i / 1000) * 20000;
  const long w = 12000 + static_cast<long>(i % 7) * 500, d = 9000 + static_cast<long>(i % 5) * 300, h = 6000, r = 9000;
  const long pts[10][3] = {{x, y, 0}, {x + w, y, 0}, {x + w, y + d, 0}, {x, y + d, 0}, {x, y, h}, {x + w, y, h},
                           {x + w, y + d, h}, {x, y + d, h}, {x, y + d / 2, r}, {x + w, y + d / 2, r}};
  for (const auto& p : pts) {
    if (!vertices.empty()) vertices += ',';
    vertices += "[" + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + "]";
  }
  auto n = [&](int k) { return std::to_string(v0 + static_cast<std::size_t>(k)); };
  const std::string id = "NL.GEN.Pand." + std::to_string(i);
  std::string s = "\"" + id + "\":{\"type\":\"Building\",\"attributes\":{\"b3_h_dak_max\":9.0},\"children\":[\"" + id +
                  "-0\"]},\"" + id + "-0\":{\"type\":\"BuildingPart\",\"parents\":[\"" + id +
                  "\"],\"geometry\":[{\"type\":\"Solid\",\"lod\":\"2.2\",\"boundaries\":[[" + "[[" + n(0) + "," + n(3) +
                  "," + n(2) + "," + n(1) + "]],[[" + n(4) + "," + n(5) + "," + n(9) + "," + n(8) + "]],[[" + n(8) + "," +
                  n(9) + "," + n(6) + "," + n(7) + "]],[[" + n(0) + "," + n(1) + "," + n(5) + "," + n(4) + "]],[[" + n(1) +
                  "," + n(2) + "," + n(6) + "," + n(9) + "," + n(5) + "]],[[" + n(2) + "," + n(3) + "," + n(7) + "," + n(6) +
                  "]],[[" + n(3) + "," + n(0) + "," + n(4) + "," + n(8) + "," + n(7) + "]]" +
                  "]],\"semantics\":{\"surfaces\":[{\"type\":\"GroundSurface\"},{\"type\":\"RoofSurface\"},{\"type\":"
                  "\"WallSurface\"}],\"values\":[[0,1,1,2,2,2,2]]}}]}";
  v0 += 10;
  return s;
}

void generate(std::size_t n, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::string head = "\"transform\":{\"scale\":[0.001,0.001,0.001],\"translate\":[85000,446000,0]},"
                           "\"metadata\":{\"referenceSystem\":\"https://www.opengis.net/def/crs/EPSG/0/7415\"}";
  std::ofstream whole(dir / "gen.city.json", std::ios::binary), seq(dir / "gen.city.jsonl", std::ios::binary);
  seq << "{\"type\":\"CityJSON\",\"version\":\"2.0\",\"CityObjects\":{},\"vertices\":[]," << head << "}\n";
  whole << "{\"type\":\"CityJSON\",\"version\":\"2.0\"," << head << ",\"CityObjects\":{";
  std::string all_vertices;
  std::size_t v0 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    whole << (i ? "," : "") << building_objects(i, v0, all_vertices);
    std::size_t local = 0;
    std::string vertices;
    const std::string objects = building_objects(i, local, vertices);
    seq << "{\"type\":\"CityJSONFeature\",\"id\":\"NL.GEN.Pand." << i << "\",\"CityObjects\":{" << objects
        << "},\"vertices\":[" << vertices << "]}\n";
  }
  whole << "},\"vertices\":[" << all_vertices << "]}";
}

void measure(const std::string& path, int runs) {
  const double mb = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  simdjson::padded_string bytes = simdjson::padded_string::load(path);
  const bool seq = path.size() > 6 && path.substr(path.size() - 6) == ".jsonl";
  std::size_t numbers = 0;
  double t_dom = 0, t_walk = 0, t_sax = 0, t_cold = 0;
  if (!seq) {
    simdjson::dom::parser dom;
    t_dom = median_seconds(runs, [&] { (void)dom.parse(bytes).value(); });
    std::function<void(simdjson::ondemand::value)> walk = [&](simdjson::ondemand::value v) {
      switch (v.type().value()) {
        case simdjson::ondemand::json_type::array:
          for (auto e : v.get_array()) walk(e.value());
          break;
        case simdjson::ondemand::json_type::object:
          for (auto f : v.get_object()) walk(f.value());
          break;
        case simdjson::ondemand::json_type::number: ++numbers, (void)v.get_double().value(); break;
        default: break;
      }
    };
    simdjson::ondemand::parser od;
    t_walk = median_seconds(runs, [&] {
      numbers = 0;
      auto doc = od.iterate(bytes);
      for (auto f : doc.get_object()) walk(f.value());
    });
    // As the reader does: a fresh parser per file (its index buffers allocated and first touched).
    t_cold = median_seconds(runs, [&] {
      simdjson::ondemand::parser fresh;
      numbers = 0;
      auto doc = fresh.iterate(bytes);
      for (auto f : doc.get_object()) walk(f.value());
    });
  }
  double t_lines = 0;
  if (seq)
    t_lines = median_seconds(runs, [&] {
      simdjson::dom::parser lines;
      simdjson::dom::document_stream docs;
      if (lines.parse_many(bytes).get(docs) != simdjson::SUCCESS) throw std::runtime_error("parse_many failed");
      for (auto doc : docs) (void)doc.value();
    });
  if (!seq)
    t_sax = median_seconds(runs, [&] {
      CountingSax sax;
      nlohmann::json::sax_parse(bytes.data(), bytes.data() + bytes.size(), &sax);
    });
  std::size_t meshes = 0, faces = 0, problems_n = 0;
  double wall_read = 0;
  const double t_read = median_seconds(runs, [&] {
    std::vector<groundplan::Problem> problems;
    groundplan::gis::ReadInfo info;
    meshes = faces = 0;
    groundplan::gis::read_any(path, {}, [&](groundplan::Mesh&& m) {
      ++meshes;
      faces += m.faces.size();
    }, problems, info);
    problems_n = problems.size();
  }, &wall_read);
  std::printf("%s: %.2f MB, %zu meshes, %zu faces, %zu problems (thread CPU time, medians of %d)\n", path.c_str(), mb,
              meshes, faces, problems_n, runs);
  if (!seq) {
    std::printf("  simdjson DOM parse (%s):          %.4f s  %7.1f MB/s\n",
                simdjson::get_active_implementation()->name().c_str(), t_dom, mb / t_dom);
    std::printf("  simdjson On-Demand walk (%s): %.4f s  %7.1f MB/s  (%zu numbers)\n",
                simdjson::builtin_implementation()->name().c_str(), t_walk, mb / t_walk, numbers);
    std::printf("  the same with a fresh parser:       %.4f s  %7.1f MB/s\n", t_cold, mb / t_cold);
    std::printf("  nlohmann-json SAX, counting only:   %.4f s  %7.1f MB/s\n", t_sax, mb / t_sax);
  }
  std::printf("  read_any -> meshes:                 %.4f s  %7.1f MB/s  (wall %.4f s)\n", t_read, mb / t_read, wall_read);
  if (!seq) std::printf("  read_any / DOM parse alone:         %.2f\n", t_read / t_dom);
  if (seq) {
    std::printf("  simdjson parse_many, all lines (%s): %.4f s  %7.1f MB/s\n",
                simdjson::get_active_implementation()->name().c_str(), t_lines, mb / t_lines);
    std::printf("  read_any / parse_many alone:        %.2f\n", t_read / t_lines);
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc >= 4 && std::string(argv[1]) == "--generate") {
      const std::size_t n = std::strtoull(argv[2], nullptr, 10);
      const int runs = argc > 4 ? std::max(1, std::atoi(argv[4])) : 5;
      generate(n, argv[3]);
      measure((std::filesystem::path(argv[3]) / "gen.city.json").string(), runs);
      measure((std::filesystem::path(argv[3]) / "gen.city.jsonl").string(), runs);
      return 0;
    }
    if (argc < 2) {
      std::fprintf(stderr, "usage: %s FILE [runs] | --generate N DIR [runs]\n", argv[0]);
      return 2;
    }
    measure(argv[1], argc > 2 ? std::max(1, std::atoi(argv[2])) : 5);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cityjson_read_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}

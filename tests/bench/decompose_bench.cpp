// SPDX-License-Identifier: MIT
// Footprints per second by surface decomposition (issue 5 goal: >= 200k LoD2 buildings/s per core),
// on one core, against the explicit GroundSurface path on the same buildings. Meshes are read once
// into memory (GroundSurface faces removed for the decomposition, so it cannot take them); the
// figure is the median of repeated passes. Usage: decompose_bench [file ...] (default: every real
// CityGML sample with GroundSurfaces, grouped per file, plus the LoD1 tiles). `--passes N` runs exactly N
// decomposition passes per file instead and no timing (for instruction counts under
// `valgrind --tool=callgrind --toggle-collect='groundplan::footprint::decompose_footprint*'`).
#include "footprint/decompose.h"

#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "test_config.h"
#include "test_support.h"

namespace {

using namespace groundplan;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

using test::without_ground;

/// Median seconds of one pass of f over ~0.5 s of passes (at least 5).
template <class F>
double median_seconds(F&& f) {
  std::vector<double> t;
  double spent = 0;
  while (spent < 0.5 || t.size() < 5) {
    const auto t0 = Clock::now();
    f();
    t.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    spent += t.back();
  }
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

struct Set {
  std::string name;
  std::vector<Mesh> full, bare;  // with and without GroundSurface faces
  std::size_t faces = 0;
};

Set load(const std::string& path, bool ground_only) {
  Set s;
  s.name = fs::path(path).filename().string();
  std::vector<Problem> problems;
  gis::SourceInfo info;
  std::vector<Mesh> meshes;
  gis::read_citygml(path, {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
  std::unique_ptr<gis::WorkingFrame> frame;
  try {
    frame = std::make_unique<gis::WorkingFrame>(info.srs_name, gis::CrsOptions{}, path);
  } catch (const std::exception&) {
  }
  for (Mesh& m : meshes) {
    const bool ground = std::any_of(m.faces.begin(), m.faces.end(), [](const MeshFace& f) { return f.kind == SurfaceKind::Ground; });
    if (ground_only && !ground) continue;
    if (frame && !frame->identity() && !frame->transform(m)) continue;
    s.bare.push_back(without_ground(m));
    s.faces += s.bare.back().faces.size();
    s.full.push_back(std::move(m));
  }
  return s;
}

int g_passes = 0;  // > 0: that many decomposition passes, no timing

void run(const Set& s) {
  if (s.bare.empty()) return;
  std::size_t sink = 0;
  if (g_passes > 0) {
    for (int p = 0; p < g_passes; ++p)
      for (const Mesh& m : s.bare) sink += footprint::decompose_footprint(m).polygons.size();
    std::printf("%-58s %6zu bldg x %d passes = %zu calls  [%zu]\n", s.name.c_str(), s.bare.size(), g_passes,
                s.bare.size() * g_passes, sink % 10);
    return;
  }
  const double dec = median_seconds([&] {
    for (const Mesh& m : s.bare) sink += footprint::decompose_footprint(m).polygons.size();
  });
  FootprintParams gp;
  gp.source = FootprintSource::GroundSurface;
  const double expl = median_seconds([&] {
    for (const Mesh& m : s.full) sink += make_footprint(m, gp).footprint.polygons.size();
  });
  const double n = static_cast<double>(s.bare.size());
  std::printf("%-58s %6zu bldg %6.1f faces/bldg  decompose %9.0f bldg/s (%6.2f us)  explicit %9.0f bldg/s  [%zu]\n",
              s.name.c_str(), s.bare.size(), s.faces / n, n / dec, 1e6 * dec / n, n / expl, sink % 10);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::pair<std::string, bool>> files;
  int first = 1;
  if (argc > 2 && std::string(argv[1]) == "--passes") {
    g_passes = std::max(1, std::atoi(argv[2]));
    first = 3;
  }
  if (argc > first) {
    for (int i = first; i < argc; ++i) files.emplace_back(argv[i], false);
  } else {
    const std::string d = GROUNDPLAN_SHARED_DATA_DIR;
    for (const char* f : {"/citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml",
                          "/citygml-citygml4j-samples/lod2_buildings_v3.gml",
                          "/citygml-fzkhaus-denhaag-misc/DenHaag_1BwBP.gml",
                          "/citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml",
                          "/citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml",
                          "/citygml-ogc-spec-samples/plateau_53394517_bldg_6697_2_op_CityGML2.gml",
                          "/citygml-fzkhaus-denhaag-misc/TUM-Main-Entrance.gml"})
      files.emplace_back(d + f, true);
    // LoD1 solids without GroundSurface: the decomposition on whole tiles.
    files.emplace_back(d + "/citygml1-niedersachsen-lod1-4tiles/LoD1_24065860_2_2021-01-25.gml", false);
    files.emplace_back(d + "/citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml", false);
  }
  for (const auto& [path, ground_only] : files) {
    try {
      run(load(path, ground_only));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), e.what());
    }
  }
  return 0;
}

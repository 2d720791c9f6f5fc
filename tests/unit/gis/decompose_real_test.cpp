// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (issue 5) against the GroundSurface footprints of every real
// CityGML file in sample_data/, tests/data/ and the third-party folder that has GroundSurfaces. The decomposition gets
// the mesh with its GroundSurface faces removed, so it cannot take them; agreement means a symmetric
// difference within 1 % of the GroundSurface footprint's area (GEOS).
#include "footprint/decompose.h"

#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/geos_reference.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>

#include "test_support.h"

namespace groundplan {
namespace {

namespace fs = std::filesystem;

using test::without_ground;

struct FileResult {
  std::string file;
  std::size_t buildings = 0, agree = 0, exact = 0;  // exact: symdiff within 1e-6 of the area
  double worst = 0;                                  // largest symdiff / area
  std::vector<std::string> outliers;
};


FileResult run_file(const std::string& path) {
  FileResult fr;
  fr.file = fs::path(path).parent_path().filename().string() + "/" + fs::path(path).filename().string();
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  gis::SourceInfo info;
  gis::read_citygml(path, {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
  // Geographic files (PLATEAU, EPSG:6697) into UTM metres: the tolerances are metric.
  std::unique_ptr<gis::WorkingFrame> frame;
  try {
    frame = std::make_unique<gis::WorkingFrame>(info.srs_name, gis::CrsOptions{}, path);
  } catch (const std::exception&) {
    frame.reset();
  }
  for (Mesh& m : meshes) {
    if (std::none_of(m.faces.begin(), m.faces.end(), [](const MeshFace& f) { return f.kind == SurfaceKind::Ground; }))
      continue;
    if (frame && !frame->identity() && !frame->transform(m)) continue;
    FootprintParams gp;
    gp.source = FootprintSource::GroundSurface;
    const FootprintResult ground = make_footprint(m, gp);
    if (!ground.ok || ground.method != FootprintMethod::GroundSurface) continue;
    ++fr.buildings;
    const footprint::DecomposeResult dec = footprint::decompose_footprint(without_ground(m));
    Footprint ours;
    ours.polygons = dec.polygons;
    const std::vector<GroundPlan> ours_union = gis::geos_union({ours});
    const gis::GeosComparison c = gis::compare_with_geos({ground.footprint}, ours_union);
    const double rel = c.area_geos > 0 ? c.symdiff_area / c.area_geos : 1;
    fr.worst = std::max(fr.worst, rel);
    fr.exact += rel <= 1e-6;
    if (rel <= 0.01) {
      ++fr.agree;
      continue;
    }
    char line[512];
    std::snprintf(line, sizeof line,
                  "%s: ground %.2f m2, decomposition %.2f m2, symdiff %.2f m2 (%.1f %%); faces %zu, loops %zu, "
                  "open chains %zu, holes %zu, dropped %zu, T-splits %zu, non-manifold %zu, parts %zu",
                  m.source_id.c_str(), c.area_geos, c.area_ours, c.symdiff_area, 100 * rel, dec.stats.faces_used,
                  dec.stats.loops, dec.stats.open_chains, dec.stats.holes, dec.stats.dropped_loops,
                  dec.stats.t_junction_splits, dec.stats.nonmanifold_edges, dec.stats.components);
    fr.outliers.push_back(line);
  }
  return fr;
}

// Once over the samples in the repository, once over the third-party ones (ThirdParty/..., skipped without them).
class DecomposeReal : public ::testing::TestWithParam<test::Samples> {};
INSTANTIATE_TEST_SUITE_P(InRepo, DecomposeReal, ::testing::Values(test::Samples::InRepo));
INSTANTIATE_TEST_SUITE_P(ThirdParty, DecomposeReal, ::testing::Values(test::Samples::ThirdParty));

TEST_P(DecomposeReal, AgreesWithGroundSurface) {
  GROUNDPLAN_SKIP_IF_NO_SAMPLES(GetParam());
  std::size_t total = 0, agree = 0, files = 0;
  for (const std::string& path : test::real_sample_files(GetParam(), {".gml", ".citygml"})) {
    FileResult fr;
    try {
      fr = run_file(path);
    } catch (const std::exception& e) {
      ADD_FAILURE() << path << ": " << e.what();
      continue;
    }
    if (fr.buildings == 0) continue;
    ++files;
    total += fr.buildings;
    agree += fr.agree;
    std::printf("%-76s %4zu buildings, %4zu within 1 %% (%5.1f %%), %4zu within 1e-6, worst %.2g\n", fr.file.c_str(),
                fr.buildings, fr.agree, 100.0 * fr.agree / fr.buildings, fr.exact, fr.worst);
    for (const std::string& o : fr.outliers) std::printf("    outlier %s\n", o.c_str());
  }
  std::printf("all: %zu files, %zu buildings, %zu within 1 %% (%.2f %%)\n", files, total, agree, 100.0 * agree / std::max<std::size_t>(total, 1));
  // 2 buildings with a GroundSurface in the repository (TUM, libcitygml's b1), 190 in the third-party samples.
  ASSERT_GT(total, GetParam() == test::Samples::InRepo ? 1u : 148u) << "the real samples were not found";
  EXPECT_GE(static_cast<double>(agree) / total, 0.99);
}

}  // namespace
}  // namespace groundplan

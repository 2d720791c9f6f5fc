// SPDX-License-Identifier: MIT
// What each level-of-detail setting removes on the real samples: plans, holes, holes under 1e-3 m2,
// neighbours closer than 1 mm, relative area change against the exact union, vertices, validity and
// overlaps (GEOS), what a GEOS closing of width D would still add, and the time. Prints a Markdown table
// per sample: docs/level_of_detail.md holds its output on the bundled samples without the times (regenerated
// and compared by the docs_examples test), tests/bench/RESULTS.md the full output.
//   lod_report [--no-times] [sample ...]   (paths to files or folders; default: every real sample)
#include <groundplan/gis/pipeline.h>
#include <groundplan/level_of_detail.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "lod_metrics.h"
#include "test_support.h"

using namespace groundplan;

namespace {

struct Setting {
  std::string name;
  LodParams lod;
  double resolution = 0;
  double gap_check = 0;  // width of the GEOS closing used to look for gaps left
};

std::vector<Setting> settings() {
  std::vector<Setting> s;
  s.push_back({"exact", {}, 0, 0.098});
  for (double d : {0.001, 0.01, 0.1}) s.push_back({"--snap " + std::to_string(d).substr(0, 5), {.snap_m = d}, 0, 0});
  for (double d : {0.05, 0.1, 0.5, 1.0})
    s.push_back({"--close-gaps " + std::to_string(d).substr(0, 4), {.close_gaps_m = d}, 0, d * 0.98});
  for (double t : {0.01, 0.1, 0.5})
    s.push_back({"--simplify " + std::to_string(t).substr(0, 4), {.simplify_m = t}, 0, 0});
  for (double r : {0.5, 1.0})
    s.push_back({"--resolution " + std::to_string(r).substr(0, 3) + " --resolution-mode raster", {.raster = true}, r, 0});
  s.push_back({"--preset cfd", gis::lod_preset("cfd"), 0, 0.49});
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> samples;
  bool times = true;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--no-times")
      times = false;
    else
      samples.push_back(argv[i]);
  }
  if (samples.empty())
    samples = {test::sample_data("plateau-niiza/53395404_bldg_6697_op.gml"),
               test::sample_data("niedersachsen-lorup/LoD1_24065862_2_2021-01-25.gml"),
               test::sample_data("tum-main-entrance/TUM-Main-Entrance.gml"),
               test::shared_data("citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml"),
               test::shared_data("citygml1-niedersachsen-lod1-4tiles"),
               test::shared_data("citygml2-plateau-japan-lod1"),
               test::shared_data("citygml-citygml4j-samples/lod2_buildings_v3.gml"),
               test::shared_data("kml-collada-macky-google")};
  for (const std::string& path : samples) {
    gis::PipelineOptions o;
    o.inputs = {path};
    const gis::PipelineResult r = gis::run_pipeline(o);
    const testing::LodMetrics base = testing::measure_plans(r.plans, 1e-3, 1e-3, 0);
    std::printf("\n### %s\n\n%zu buildings, %zu footprints, exact union %.3f m2\n\n", path.c_str(), r.buildings_read,
                r.footprints.size(), base.area_m2);
    std::printf("| setting | plans | holes | holes < 1e-3 m2 | pairs < 1 mm apart | area change (rel.) | vertices | "
                "invalid / overlapping | GEOS closing still adds (m2) |%s\n", times ? " time (s) |" : "");
    std::printf("|---|---|---|---|---|---|---|---|---|%s\n", times ? "---|" : "");
    for (const Setting& s : settings()) {
      std::vector<Problem> problems;
      UnionParams up;
      up.resolution_m = s.resolution;
      const auto t0 = std::chrono::steady_clock::now();
      const std::vector<GroundPlan> plans = build_ground_plans(r.footprints, up, s.lod, problems, {}, nullptr);
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const testing::LodMetrics m = testing::measure_plans(plans, 1e-3, 1e-3, s.gap_check);
      char residual[32] = "";
      if (s.gap_check > 0) std::snprintf(residual, sizeof residual, "%.3g (D=%.3g)", m.closing_residual_m2, s.gap_check);
      std::printf("| `%s` | %zu | %zu | %zu | %zu | %+.2e | %zu | %zu / %zu | %s |", s.name.c_str(), m.plans, m.holes,
                  m.small_holes, m.close_pairs, (m.area_m2 - base.area_m2) / base.area_m2, m.vertices, m.invalid,
                  m.overlapping_pairs, residual);
      if (times) std::printf(" %.3f |", secs);
      std::printf("\n");
    }
  }
  return 0;
}

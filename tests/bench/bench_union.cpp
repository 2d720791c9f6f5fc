// SPDX-License-Identifier: MIT
// Union benchmark (issue 3): this engine against GEOS UnaryUnion, GEOS DisjointSubsetUnion (GEOS >= 3.12,
// the honest baseline: it unions each group of touching polygons on its own, as we do) and
// GEOSCoverageUnion where the input is a valid coverage, on identical synthetic footprints, in one
// process per (engine, size) so that peak memory (getrusage ru_maxrss) belongs to one engine.
//
//   bench_union --n 6000 --engine ours|geos|dsu|coverage [--runs 5] [--seed 1] [--threads 0] [--coverage]
//   bench_union --n 6000 --verify [--coverage]     (compare our plans with GEOS UnaryUnion, exit 1 if not)
// prints one line: engine n runs median_wall_s min_wall_s max_wall_s median_cpu_s plans peak_rss_mib
// input_rss_mib min_cpu_s (input_rss: after generating the footprints, before the first union; on a
// shared machine the least-disturbed run, min_cpu_s, is the best estimate of the unloaded cost)
// tests/bench/run_bench.sh runs the whole matrix and prints ratios.
//
// DisjointSubsetUnion is looked up at run time (dlsym), because Debian bookworm's GEOS is 3.11: the same
// binary, started with LD_LIBRARY_PATH pointing at a newer libgeos_c.so.1 (the C API's ABI is stable),
// measures it; with 3.11 `--engine dsu` exits 3 and says why. The GEOS version in use goes to stderr.
#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <dlfcn.h>
#include <geos_c.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_util.h"
#include "union_generators.h"

namespace {


using groundplan::bench::cpu_seconds;
using groundplan::bench::peak_rss_mib;

void quiet(const char*, ...) {}

using CollectionUnion = GEOSGeometry* (*)(GEOSContextHandle_t, const GEOSGeometry*);

/// `op` (GEOSCoverageUnion_r, GEOSDisjointSubsetUnion_r) of all footprint polygons as one MultiPolygon;
/// returns the number of polygons of the result.
std::size_t geos_collection_union(const std::vector<groundplan::Footprint>& fps, CollectionUnion op) {
  GEOSContextHandle_t h = GEOS_init_r();
  GEOSContext_setNoticeHandler_r(h, quiet);
  GEOSContext_setErrorHandler_r(h, quiet);
  std::vector<GEOSGeometry*> polys;
  for (const auto& f : fps)
    for (const auto& p : f.polygons) {
      auto ring = [&](const groundplan::Ring& r) {
        GEOSCoordSequence* s = GEOSCoordSeq_create_r(h, static_cast<unsigned>(r.size() + 1), 2);
        for (std::size_t i = 0; i <= r.size(); ++i)
          GEOSCoordSeq_setXY_r(h, s, static_cast<unsigned>(i), r[i % r.size()].x, r[i % r.size()].y);
        return GEOSGeom_createLinearRing_r(h, s);
      };
      std::vector<GEOSGeometry*> holes;
      for (const auto& hr : p.holes) holes.push_back(ring(hr));
      polys.push_back(GEOSGeom_createPolygon_r(h, ring(p.outer), holes.data(), static_cast<unsigned>(holes.size())));
    }
  GEOSGeometry* coll =
      GEOSGeom_createCollection_r(h, GEOS_MULTIPOLYGON, polys.data(), static_cast<unsigned>(polys.size()));
  GEOSGeometry* u = op(h, coll);
  std::size_t n = u ? static_cast<std::size_t>(GEOSGetNumGeometries_r(h, u)) : 0;
  if (u) GEOSGeom_destroy_r(h, u);
  GEOSGeom_destroy_r(h, coll);
  GEOS_finish_r(h);
  return n;
}

/// GEOSDisjointSubsetUnion_r of the libgeos_c loaded at run time, or nullptr before GEOS 3.12.
CollectionUnion disjoint_subset_union() {
  return reinterpret_cast<CollectionUnion>(dlsym(RTLD_DEFAULT, "GEOSDisjointSubsetUnion_r"));
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 6000;
  std::string engine = "ours";
  int runs = 5, threads = 0;
  std::uint64_t seed = 1;
  bool coverage = false, verify = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--n") n = std::strtoull(next(), nullptr, 10);
    else if (a == "--engine") engine = next();
    else if (a == "--runs") runs = std::atoi(next());
    else if (a == "--seed") seed = std::strtoull(next(), nullptr, 10);
    else if (a == "--threads") threads = std::atoi(next());
    else if (a == "--coverage") coverage = true;
    else if (a == "--verify") verify = true;
    else {
      std::fprintf(stderr, "usage: %s --n N --engine ours|geos|dsu|coverage [--runs R] [--seed S] [--threads T] [--coverage]\n", argv[0]);
      return 2;
    }
  }
  std::fprintf(stderr, "GEOS %s\n", GEOSversion());
  const CollectionUnion dsu = disjoint_subset_union();
  if (engine == "dsu" && !dsu) {
    std::fprintf(stderr, "--engine dsu: GEOSDisjointSubsetUnion_r needs GEOS >= 3.12, loaded %s; put a newer "
                 "libgeos_c.so.1 on LD_LIBRARY_PATH\n", GEOSversion());
    return 3;
  }
  const auto fps = groundplan::testing::synthetic_city(n, seed, coverage);
  const double input_rss = peak_rss_mib();
  if (verify) {
    // correctness of our result on this input against GEOS UnaryUnion (DESIGN.md criterion)
    groundplan::UnionParams p;
    std::vector<groundplan::Problem> problems;
    const auto plans = groundplan::build_ground_plans(fps, p, problems);
    const auto c = groundplan::gis::compare_with_geos(fps, plans);
    std::printf("verify n=%zu matches=%d problems=%zu: %s\n", fps.size(), c.matches(1e-9) ? 1 : 0, problems.size(),
                c.summary().c_str());
    return c.matches(1e-9) ? 0 : 1;
  }
  std::vector<double> t, cpu;
  std::size_t plans = 0;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    if (engine == "ours") {
      groundplan::UnionParams p;
      p.threads = threads;
      std::vector<groundplan::Problem> problems;
      plans = groundplan::build_ground_plans(fps, p, problems).size();
    } else if (engine == "geos") {
      plans = groundplan::gis::geos_union(fps).size();
    } else if (engine == "dsu") {
      plans = geos_collection_union(fps, dsu);
    } else if (engine == "coverage") {
      plans = geos_collection_union(fps, GEOSCoverageUnion_r);
    } else {
      std::fprintf(stderr, "unknown engine %s\n", engine.c_str());
      return 2;
    }
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    cpu.push_back(cpu_seconds() - c0);
  }
  std::sort(t.begin(), t.end());
  std::sort(cpu.begin(), cpu.end());
  std::printf("%s %zu %d %.6f %.6f %.6f %.6f %zu %.1f %.1f %.6f\n", engine.c_str(), fps.size(), runs, t[t.size() / 2],
              t.front(), t.back(), cpu[cpu.size() / 2], plans, peak_rss_mib(), input_rss, cpu.front());
  return 0;
}

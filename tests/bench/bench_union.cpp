// SPDX-License-Identifier: MIT
// Union benchmark (issue 3): this engine against GEOS UnaryUnion, GEOS DisjointSubsetUnion (GEOS >= 3.12,
// the honest baseline: it unions each group of touching polygons on its own, as we do) and
// GEOSCoverageUnion where the input is a valid coverage, on identical synthetic footprints, in one
// process per (engine, size) so that peak memory (getrusage ru_maxrss) belongs to one engine.
//
//   bench_union --n 6000 --engine ours|geos|dsu|coverage|clipper2|clipper2_groups|boost [--runs 5] [--seed 1]
//               [--threads 0] [--coverage] [--input FOOTPRINTS.csv] [--min-time S]
//   bench_union --n 6000 --verify [--coverage]     (compare our plans with GEOS UnaryUnion, exit 1 if not)
//   bench_union --n 60000 --profile [--runs 5]    (where our union's time goes, by block size)
//   bench_union ... --engine ours --dump FILE      (our plans and problems, every coordinate as a hex float, to
//                                                  compare two builds bit for bit)
// --input: footprints from a file of one WKT (Multi)Polygon a line (the first field, quotes and a header line
// allowed: `ogr2ogr --config OGR_WKT_PRECISION 17 -f CSV -lco GEOMETRY=AS_WKT` of a footprints layer) instead of
// the synthetic city. clipper2, clipper2_groups, boost: other libraries' unions as anchors (union_anchors.h).
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

#include <groundplan/raster_backend.h>

#include <cmath>
#include <fstream>
#include <memory>

#include "bench_util.h"
#include "union/block_union.h"
#include "union_anchors.h"
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

/// Plans (members, area, rings) and problems, coordinates as hex floats: equal files are equal plans, bit for bit.
void write_dump(const std::string& path, const std::vector<groundplan::GroundPlan>& plans,
                const std::vector<groundplan::Problem>& problems) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(2);
  }
  auto ring = [&](const char* kind, const groundplan::Ring& r) {
    std::fprintf(f, " %s", kind);
    for (const auto& p : r) std::fprintf(f, " %a,%a", p.x, p.y);
    std::fprintf(f, "\n");
  };
  for (const auto& g : plans) {
    std::fprintf(f, "plan area %a members", g.area_m2);
    for (std::uint32_t m : g.members) std::fprintf(f, " %u", m);
    std::fprintf(f, "\n");
    ring("outer", g.polygon.outer);
    for (const auto& h : g.polygon.holes) ring("hole", h);
  }
  for (const auto& p : problems)
    std::fprintf(f, "problem %s %s %s: %s\n", p.source_id.c_str(), p.stage.c_str(), p.code.c_str(), p.reason.c_str());
  std::fclose(f);
}

/// Footprints from one WKT (Multi)Polygon a line (see the head of this file); each line is one footprint.
std::vector<groundplan::Footprint> read_wkt_footprints(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "cannot read %s\n", path.c_str());
    std::exit(2);
  }
  GEOSContextHandle_t h = GEOS_init_r();
  GEOSContext_setNoticeHandler_r(h, quiet);
  GEOSContext_setErrorHandler_r(h, quiet);
  GEOSWKTReader* reader = GEOSWKTReader_create_r(h);
  std::vector<groundplan::Footprint> out;
  std::string line;
  auto ring_of = [&](const GEOSGeometry* r) {
    groundplan::Ring ring;
    const GEOSCoordSequence* s = GEOSGeom_getCoordSeq_r(h, r);
    unsigned n = 0;
    GEOSCoordSeq_getSize_r(h, s, &n);
    for (unsigned i = 0; i + 1 < n; ++i) {  // the closing point is implicit
      double x = 0, y = 0;
      GEOSCoordSeq_getXY_r(h, s, i, &x, &y);
      ring.push_back({x, y});
    }
    return ring;
  };
  while (std::getline(in, line)) {
    std::size_t a = line.find_first_not_of(" \t\"");
    if (a == std::string::npos || (line.compare(a, 7, "POLYGON") != 0 && line.compare(a, 12, "MULTIPOLYGON") != 0))
      continue;  // header or empty geometry
    const std::size_t b = line.find('"', a);
    GEOSGeometry* g = GEOSWKTReader_read_r(h, reader, line.substr(a, b == std::string::npos ? b : b - a).c_str());
    if (!g) continue;
    groundplan::Footprint f;
    f.source_id = std::to_string(out.size());
    for (int k = 0, n = GEOSGetNumGeometries_r(h, g); k < n; ++k) {
      const GEOSGeometry* p = GEOSGetGeometryN_r(h, g, k);
      groundplan::Polygon poly;
      poly.outer = ring_of(GEOSGetExteriorRing_r(h, p));
      for (int i = 0, m = GEOSGetNumInteriorRings_r(h, p); i < m; ++i)
        poly.holes.push_back(ring_of(GEOSGetInteriorRingN_r(h, p, i)));
      f.polygons.push_back(std::move(poly));
    }
    GEOSGeom_destroy_r(h, g);
    out.push_back(std::move(f));
  }
  GEOSWKTReader_destroy_r(h, reader);
  GEOS_finish_r(h);
  return out;
}

/// Where our union's time goes, by block size: the blocks as build_ground_plans finds them (boxes grown by 4
/// pitches, automatic grid, CPU raster), each united by union_block alone, summed per class of block size. The
/// classes call union_block through functions of their own, so that callgrind's inclusive counts split the same way.
constexpr std::size_t kShortcut = std::size_t{1} << 62;  // flag on a class function's plan count
__attribute__((noinline)) std::size_t union_class_1(const std::vector<groundplan::Footprint>& f,
                                                    const std::vector<std::uint32_t>& m, double pitch) {
  const auto r = groundplan::detail::union_block(f, m, pitch);
  return r.plans.size() | (r.stats.simple_rings ? kShortcut : 0);
}
__attribute__((noinline)) std::size_t union_class_2_8(const std::vector<groundplan::Footprint>& f,
                                                      const std::vector<std::uint32_t>& m, double pitch) {
  const auto r = groundplan::detail::union_block(f, m, pitch);
  return r.plans.size() | (r.stats.simple_rings ? kShortcut : 0);
}
__attribute__((noinline)) std::size_t union_class_9_up(const std::vector<groundplan::Footprint>& f,
                                                       const std::vector<std::uint32_t>& m, double pitch) {
  const auto r = groundplan::detail::union_block(f, m, pitch);
  return r.plans.size() | (r.stats.simple_rings ? kShortcut : 0);
}

int profile(const std::vector<groundplan::Footprint>& fps, int runs) {
  using namespace groundplan;
  const auto t0 = std::chrono::steady_clock::now();
  FootprintSet set = make_footprint_set(fps);
  double max_abs = 0;
  for (const auto& b : set.boxes) max_abs = std::max({max_abs, std::fabs(b.minx), std::fabs(b.miny), std::fabs(b.maxx), std::fabs(b.maxy)});
  const double pitch = snap_pitch(max_abs);
  for (auto& b : set.boxes) b = {b.minx - 4 * pitch, b.miny - 4 * pitch, b.maxx + 4 * pitch, b.maxy + 4 * pitch};
  const PixelGrid grid = make_pixel_grid(set, 0);
  const std::vector<Block> blocks = make_raster_backend(Device::Cpu)->find_blocks(set, grid, Progress{});
  const double blocks_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  struct Class {
    const char* name;
    std::size_t lo, hi;
    std::size_t (*fn)(const std::vector<Footprint>&, const std::vector<std::uint32_t>&, double);
    std::size_t blocks = 0, footprints = 0, vertices = 0, plans = 0, shortcut = 0;
    std::vector<double> s;
  };
  Class classes[] = {{"1", 1, 1, union_class_1, 0, 0, 0, 0, 0, {}},
                     {"2-8", 2, 8, union_class_2_8, 0, 0, 0, 0, 0, {}},
                     {"9+", 9, SIZE_MAX, union_class_9_up, 0, 0, 0, 0, 0, {}}};
  std::vector<double> block_pitch(blocks.size());
  std::size_t largest = 0;
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    double m = 0;
    for (std::uint32_t fi : blocks[bi].footprints)
      for (const auto& p : fps[fi].polygons)
        for (const auto& q : p.outer) m = std::max({m, std::fabs(q.x), std::fabs(q.y)});
    block_pitch[bi] = snap_pitch(m);
    largest = std::max(largest, blocks[bi].footprints.size());
    for (Class& c : classes) {
      if (blocks[bi].footprints.size() < c.lo || blocks[bi].footprints.size() > c.hi) continue;
      ++c.blocks;
      c.footprints += blocks[bi].footprints.size();
      for (std::uint32_t fi : blocks[bi].footprints)
        for (const auto& p : fps[fi].polygons) {
          c.vertices += p.outer.size();
          for (const auto& hr : p.holes) c.vertices += hr.size();
        }
    }
  }
  for (int r = 0; r < runs; ++r)
    for (Class& c : classes) {
      const auto a = std::chrono::steady_clock::now();
      c.plans = c.shortcut = 0;
      for (std::size_t bi = 0; bi < blocks.size(); ++bi)
        if (blocks[bi].footprints.size() >= c.lo && blocks[bi].footprints.size() <= c.hi) {
          const std::size_t r = c.fn(fps, blocks[bi].footprints, block_pitch[bi]);
          c.plans += r & ~kShortcut;
          c.shortcut += (r & kShortcut) != 0;
        }
      c.s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
    }
  std::printf("footprints %zu blocks %zu largest_block %zu blocks_stage_s %.6f (one run, with the raster's setup)\n",
              fps.size(), blocks.size(), largest, blocks_s);
  std::printf("class blocks footprints vertices plans median_s us_per_footprint shortcut_blocks\n");
  for (Class& c : classes) {
    std::sort(c.s.begin(), c.s.end());
    const double med = c.s.empty() ? 0 : c.s[c.s.size() / 2];
    std::printf("%s %zu %zu %zu %zu %.6f %.3f %zu\n", c.name, c.blocks, c.footprints, c.vertices, c.plans, med,
                c.footprints ? 1e6 * med / static_cast<double>(c.footprints) : 0.0, c.shortcut);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 6000;
  std::string engine = "ours";
  int runs = 5, threads = 0;
  double min_time = 0;  // small inputs: a timed run repeats the call until this much CPU time, timed per call
  std::uint64_t seed = 1;
  bool coverage = false, verify = false, prof = false;
  std::string input, dump;
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
    else if (a == "--profile") prof = true;
    else if (a == "--input") input = next();
    else if (a == "--dump") dump = next();
    else if (a == "--min-time") min_time = std::atof(next());
    else {
      std::fprintf(stderr, "usage: %s --n N --engine ours|geos|dsu|coverage|clipper2|clipper2_groups|boost [--runs R] "
                   "[--seed S] [--threads T] [--coverage] [--input FILE] [--verify] [--profile]\n", argv[0]);
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
  const auto fps = input.empty() ? groundplan::testing::synthetic_city(n, seed, coverage) : read_wkt_footprints(input);
  const double input_rss = peak_rss_mib();
  if (prof) return profile(fps, runs);
  std::unique_ptr<groundplan::bench::Anchor> anchor;
  if (engine != "ours" && engine != "geos" && engine != "dsu" && engine != "coverage") {
    std::string why;
    anchor = groundplan::bench::make_anchor(engine, fps, why);
    if (!anchor) {
      std::fprintf(stderr, "--engine %s: %s\n", engine.c_str(), why.c_str());
      return why.rfind("unknown", 0) == 0 ? 2 : 3;
    }
  }
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
    int calls = 0;
    for (int rep = 0; rep == 0 || cpu_seconds() - c0 < min_time; ++rep, ++calls) {
    if (engine == "ours") {
      groundplan::UnionParams p;
      p.threads = threads;
      std::vector<groundplan::Problem> problems;
      const auto result = groundplan::build_ground_plans(fps, p, problems);
      plans = result.size();
      if (!dump.empty() && r == 0 && rep == 0) write_dump(dump, result, problems);
    } else if (engine == "geos") {
      plans = groundplan::gis::geos_union(fps).size();
    } else if (engine == "dsu") {
      plans = geos_collection_union(fps, dsu);
    } else if (engine == "coverage") {
      plans = geos_collection_union(fps, GEOSCoverageUnion_r);
    } else if (anchor) {
      plans = anchor->run();
    } else {
      std::fprintf(stderr, "unknown engine %s\n", engine.c_str());
      return 2;
    }
    }
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / calls);
    cpu.push_back((cpu_seconds() - c0) / calls);
  }
  std::sort(t.begin(), t.end());
  std::sort(cpu.begin(), cpu.end());
  std::printf("%s %zu %d %.6f %.6f %.6f %.6f %zu %.1f %.1f %.6f\n", engine.c_str(), fps.size(), runs, t[t.size() / 2],
              t.front(), t.back(), cpu[cpu.size() / 2], plans, peak_rss_mib(), input_rss, cpu.front());
  return 0;
}

// SPDX-License-Identifier: MIT
// Level-of-detail benchmark (issue 9): our LoD steps (build_ground_plans with LodParams) against what
// users would otherwise do with GEOS, on identical synthetic footprints, one process per (op, n) so
// that peak memory (getrusage ru_maxrss) belongs to one operation.
//
//   bench_lod --n 10000 --op OP [--d 0.5] [--runs 5] [--seed 1] [--threads 0]
//     OP, ours (build_ground_plans with LodParams set directly; LodParams{} is the exact union):
//       union         exact union alone
//       close         union + --close-gaps D
//       snap          --snap 0.01, then union
//       simplify      union + --simplify 0.1
//       cfd           the values of --preset cfd: snap 0.01, close 0.5, simplify 0.1, min hole area 1, min area 1
//     OP, GEOS (C API, one context, single thread; the collection is built inside the timed region):
//       geos_union    GEOSUnaryUnion_r of all footprint polygons
//       geos_close    GEOSUnaryUnion_r, GEOSBufferWithParams_r(+D/2), then (-D/2): mitre joins, mitre limit 10
//       geos_snap     GEOSUnaryUnionPrec_r(grid 0.01): snap rounding to a 1 cm grid (NOT the same operation
//                     as our --snap, which moves vertices onto vertices/edges within D and keeps the rest)
//       geos_simplify GEOSUnaryUnion_r, then GEOSTopologyPreserveSimplify_r(0.1)
//       geos_cfd      GEOSUnaryUnionPrec_r(0.01), closing by 0.5 as geos_close, TopologyPreserveSimplify(0.1)
//                     (no hole / area filters: those are cheap and not the point)
//   prints one line: op n runs d median_wall_s min_wall_s max_wall_s median_cpu_s median_step_s plans holes
//   vertices area_m2 peak_rss_mib input_rss_mib min_cpu_s
//   (step: the LoD step alone, ours from LodStats (snap_s / close_s / simplify_s; cfd: all steps), GEOS
//   the buffers / the simplification / the whole precision union; for union ops the whole time)
//
//   bench_lod --matrix "10000 100000" [--geos-max 100000] [--runs R] [--geos-runs-big 1]
//     runs every op in its own process (this binary again) and prints the lines, then the ratios
//     GEOS / ours and the area and plan counts of both closings. Runs: ours R (default 5 below 100k,
//     3 from 100k), GEOS 3 below 100k and --geos-runs-big (default 1) from 100k; GEOS is not run
//     above --geos-max footprints.
#include <groundplan/level_of_detail.h>

#include <geos_c.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "union_generators.h"

namespace {


using groundplan::bench::cpu_seconds;
using groundplan::bench::peak_rss_mib;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void quiet(const char*, ...) {}

struct Result {
  std::size_t plans = 0, holes = 0, vertices = 0;
  double area_m2 = 0;
  double step_s = 0;
};

// ---- ours ------------------------------------------------------------------------------------------

Result run_ours(const std::vector<groundplan::Footprint>& fps, const std::string& op, double d, int threads) {
  groundplan::UnionParams up;
  up.threads = threads;
  groundplan::LodParams lod;
  if (op == "close") lod.close_gaps_m = d;
  else if (op == "snap") lod.snap_m = 0.01;
  else if (op == "simplify") lod.simplify_m = 0.1;
  else if (op == "cfd") {
    lod.snap_m = 0.01;
    lod.close_gaps_m = 0.5;
    lod.simplify_m = 0.1;
    lod.min_hole_area_m2 = 1;
    lod.min_area_m2 = 1;
  }
  std::vector<groundplan::Problem> problems;
  groundplan::LodStats st;
  const auto t0 = std::chrono::steady_clock::now();
  const auto plans = groundplan::build_ground_plans(fps, up, lod, problems, {}, &st);
  const double total = seconds_since(t0);
  Result r;
  r.plans = plans.size();
  for (const auto& p : plans) {
    r.area_m2 += p.area_m2;
    r.holes += p.polygon.holes.size();
    r.vertices += p.polygon.outer.size();
    for (const auto& h : p.polygon.holes) r.vertices += h.size();
  }
  if (op == "close") r.step_s = st.close_s;
  else if (op == "snap") r.step_s = st.snap_s;
  else if (op == "simplify") r.step_s = st.simplify_s;
  else if (op == "cfd") r.step_s = st.snap_s + st.close_s + st.raster_s + st.simplify_s + st.filter_s;
  else r.step_s = total;
  return r;
}

// ---- GEOS ------------------------------------------------------------------------------------------

struct Geos {
  GEOSContextHandle_t h = GEOS_init_r();
  Geos() {
    GEOSContext_setNoticeHandler_r(h, quiet);
    GEOSContext_setErrorHandler_r(h, quiet);
  }
  ~Geos() { GEOS_finish_r(h); }
  Geos(const Geos&) = delete;
  Geos& operator=(const Geos&) = delete;
};

GEOSGeometry* to_geos(GEOSContextHandle_t h, const std::vector<groundplan::Footprint>& fps) {
  std::vector<GEOSGeometry*> polys;
  auto ring = [&](const groundplan::Ring& r) {
    GEOSCoordSequence* s = GEOSCoordSeq_create_r(h, static_cast<unsigned>(r.size() + 1), 2);
    for (std::size_t i = 0; i <= r.size(); ++i)
      GEOSCoordSeq_setXY_r(h, s, static_cast<unsigned>(i), r[i % r.size()].x, r[i % r.size()].y);
    return GEOSGeom_createLinearRing_r(h, s);
  };
  for (const auto& f : fps)
    for (const auto& p : f.polygons) {
      if (p.outer.size() < 3) continue;
      std::vector<GEOSGeometry*> holes;
      for (const auto& hr : p.holes)
        if (hr.size() >= 3) holes.push_back(ring(hr));
      polys.push_back(GEOSGeom_createPolygon_r(h, ring(p.outer), holes.data(), static_cast<unsigned>(holes.size())));
    }
  return GEOSGeom_createCollection_r(h, GEOS_MULTIPOLYGON, polys.data(), static_cast<unsigned>(polys.size()));
}

void measure(GEOSContextHandle_t h, const GEOSGeometry* g, Result& r) {
  if (!g) {
    std::fprintf(stderr, "GEOS returned no geometry\n");
    std::exit(1);
  }
  GEOSArea_r(h, g, &r.area_m2);
  const int n = GEOSGetNumGeometries_r(h, g);
  r.plans = 0;
  r.holes = 0;
  r.vertices = 0;
  for (int i = 0; i < n; ++i) {
    const GEOSGeometry* p = GEOSGetGeometryN_r(h, g, i);
    if (GEOSGeomTypeId_r(h, p) != GEOS_POLYGON || GEOSisEmpty_r(h, p)) continue;
    ++r.plans;
    const int nh = GEOSGetNumInteriorRings_r(h, p);
    r.holes += static_cast<std::size_t>(nh);
    // closed rings repeat their first point: count distinct ring vertices as ours does
    r.vertices += static_cast<std::size_t>(GEOSGetNumCoordinates_r(h, p)) - static_cast<std::size_t>(1 + nh);
  }
}

Result run_geos(const std::vector<groundplan::Footprint>& fps, const std::string& op, double d) {
  Geos g;
  Result r;
  GEOSGeometry* all = to_geos(g.h, fps);
  GEOSGeometry* out = nullptr;
  GEOSBufferParams* bp = GEOSBufferParams_create_r(g.h);
  GEOSBufferParams_setJoinStyle_r(g.h, bp, GEOSBUF_JOIN_MITRE);
  GEOSBufferParams_setMitreLimit_r(g.h, bp, 10.0);
  auto closing = [&](GEOSGeometry* u, double width) {
    GEOSGeometry* dil = GEOSBufferWithParams_r(g.h, u, bp, width / 2);
    GEOSGeometry* clo = dil ? GEOSBufferWithParams_r(g.h, dil, bp, -width / 2) : nullptr;
    if (dil) GEOSGeom_destroy_r(g.h, dil);
    return clo;
  };
  const auto t0 = std::chrono::steady_clock::now();
  if (op == "geos_union") {
    out = GEOSUnaryUnion_r(g.h, all);
  } else if (op == "geos_close") {
    GEOSGeometry* u = GEOSUnaryUnion_r(g.h, all);
    const auto t1 = std::chrono::steady_clock::now();
    out = u ? closing(u, d) : nullptr;
    r.step_s = seconds_since(t1);
    if (u) GEOSGeom_destroy_r(g.h, u);
  } else if (op == "geos_snap") {
    out = GEOSUnaryUnionPrec_r(g.h, all, 0.01);
  } else if (op == "geos_simplify") {
    GEOSGeometry* u = GEOSUnaryUnion_r(g.h, all);
    const auto t1 = std::chrono::steady_clock::now();
    out = u ? GEOSTopologyPreserveSimplify_r(g.h, u, 0.1) : nullptr;
    r.step_s = seconds_since(t1);
    if (u) GEOSGeom_destroy_r(g.h, u);
  } else if (op == "geos_cfd") {
    GEOSGeometry* u = GEOSUnaryUnionPrec_r(g.h, all, 0.01);
    GEOSGeometry* c = u ? closing(u, 0.5) : nullptr;
    out = c ? GEOSTopologyPreserveSimplify_r(g.h, c, 0.1) : nullptr;
    if (c) GEOSGeom_destroy_r(g.h, c);
    if (u) GEOSGeom_destroy_r(g.h, u);
  } else {
    std::fprintf(stderr, "unknown op %s\n", op.c_str());
    std::exit(2);
  }
  const double total = seconds_since(t0);
  if (op == "geos_union" || op == "geos_snap" || op == "geos_cfd") r.step_s = total;
  measure(g.h, out, r);
  GEOSGeom_destroy_r(g.h, out);
  GEOSBufferParams_destroy_r(g.h, bp);
  GEOSGeom_destroy_r(g.h, all);
  return r;
}

// ---- one (op, n) -----------------------------------------------------------------------------------

int run_one(std::size_t n, const std::string& op, double d, int runs, std::uint64_t seed, int threads) {
  const auto fps = groundplan::testing::synthetic_city(n, seed);
  const double input_rss = peak_rss_mib();
  const bool geos = op.rfind("geos_", 0) == 0;
  std::vector<double> t, cpu, step;
  Result res;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    res = geos ? run_geos(fps, op, d) : run_ours(fps, op, d, threads);
    t.push_back(seconds_since(t0));
    cpu.push_back(cpu_seconds() - c0);
    step.push_back(res.step_s);
  }
  std::sort(t.begin(), t.end());
  std::sort(cpu.begin(), cpu.end());
  std::sort(step.begin(), step.end());
  std::printf("%s %zu %d %g %.6f %.6f %.6f %.6f %.6f %zu %zu %zu %.6f %.1f %.1f %.6f\n", op.c_str(), fps.size(), runs,
              d, t[t.size() / 2], t.front(), t.back(), cpu[cpu.size() / 2], step[step.size() / 2], res.plans,
              res.holes, res.vertices, res.area_m2, peak_rss_mib(), input_rss, cpu.front());
  std::fflush(stdout);
  return 0;
}

// ---- the matrix ------------------------------------------------------------------------------------

struct Line {
  std::string op;
  std::size_t n = 0;
  int runs = 0;
  double d = 0, wall = 0, wmin = 0, wmax = 0, cpu = 0, step = 0;
  std::size_t plans = 0, holes = 0, vertices = 0;
  double area = 0, rss = 0, input_rss = 0, cpu_min = 0;
};

std::string self_path() {
  char buf[4096];
  const ssize_t len = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (len <= 0) return "bench_lod";
  return std::string(buf, static_cast<std::size_t>(len));
}

bool run_child(const std::string& args, Line& line) {
  static const std::string self = self_path();
  const std::string cmd = "'" + self + "' " + args;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return false;
  char buf[1024];
  std::string out;
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int rc = pclose(p);
  std::fputs(out.c_str(), stdout);
  std::fflush(stdout);
  if (rc != 0) return false;
  std::istringstream in(out);
  in >> line.op >> line.n >> line.runs >> line.d >> line.wall >> line.wmin >> line.wmax >> line.cpu >> line.step >>
      line.plans >> line.holes >> line.vertices >> line.area >> line.rss >> line.input_rss >> line.cpu_min;
  return static_cast<bool>(in);
}

std::string key(const std::string& op, double d) {
  char b[64];
  std::snprintf(b, sizeof b, "%s/%g", op.c_str(), d);
  return b;
}

int run_matrix(const std::string& sizes, std::size_t geos_max, int runs_arg, int geos_runs_big, std::uint64_t seed,
               int threads) {
  std::printf("op n runs d median_wall_s min_wall_s max_wall_s median_cpu_s median_step_s plans holes vertices "
              "area_m2 peak_rss_mib input_rss_mib min_cpu_s\n");
  std::istringstream ss(sizes);
  std::size_t n = 0;
  bool ok = true;
  std::vector<std::pair<std::size_t, std::map<std::string, Line>>> all;
  while (ss >> n) {
    std::map<std::string, Line> lines;
    const int runs = runs_arg > 0 ? runs_arg : (n >= 100000 ? 3 : 5);
    const int gruns = runs_arg > 0 ? runs_arg : (n >= 100000 ? geos_runs_big : 3);
    auto go = [&](const std::string& op, double d, int r) {
      char args[256];
      std::snprintf(args, sizeof args, "--n %zu --op %s --d %g --runs %d --seed %llu --threads %d", n, op.c_str(), d,
                    r, static_cast<unsigned long long>(seed), threads);
      Line l;
      if (run_child(args, l)) lines[key(op, d)] = l;
      else {
        std::fprintf(stderr, "failed: %s\n", args);
        ok = false;
      }
    };
    const std::pair<const char*, double> ops[] = {{"union", 0},  {"close", 0.1},   {"close", 0.5},
                                                  {"snap", 0},   {"simplify", 0}, {"cfd", 0}};
    for (const std::string prefix : {"", "geos_"}) {
      if (!prefix.empty() && n > geos_max) continue;
      for (const auto& [op, d] : ops) go(prefix + op, d, prefix.empty() ? runs : gruns);
    }
    all.emplace_back(n, std::move(lines));
  }

  // ratios: whole operation (wall, medians) and the LoD step alone
  std::printf("\nratios (GEOS median wall / ours median wall; step: the LoD step alone)\n");
  std::printf("n what ours_s geos_s ratio ours_step_s geos_step_s step_ratio ours_rss_mib geos_rss_mib\n");
  struct Pair {
    const char* what;
    std::string ours, geos;
  };
  const Pair pairs[] = {{"union", key("union", 0), key("geos_union", 0)},
                        {"close_0.1", key("close", 0.1), key("geos_close", 0.1)},
                        {"close_0.5", key("close", 0.5), key("geos_close", 0.5)},
                        {"snap_0.01_vs_prec_union", key("snap", 0), key("geos_snap", 0)},
                        {"simplify_0.1", key("simplify", 0), key("geos_simplify", 0)},
                        {"cfd", key("cfd", 0), key("geos_cfd", 0)}};
  for (const auto& [sz, lines] : all)
    for (const auto& p : pairs) {
      const auto o = lines.find(p.ours);
      if (o == lines.end()) continue;
      const auto g = lines.find(p.geos);
      if (g == lines.end()) {
        std::printf("%zu %s %.4f - - %.4f - - %.1f -\n", sz, p.what, o->second.wall, o->second.step, o->second.rss);
        continue;
      }
      std::printf("%zu %s %.4f %.4f %.1fx %.4f %.4f %.1fx %.1f %.1f\n", sz, p.what, o->second.wall, g->second.wall,
                  g->second.wall / o->second.wall, o->second.step, g->second.step, g->second.step / o->second.step,
                  o->second.rss, g->second.rss);
    }

  // sanity: our closing against the GEOS closing of the same width
  std::printf("\nresults (area change relative to our exact union; plans / holes / vertices)\n");
  std::printf("n op area_m2 rel_change plans holes vertices\n");
  for (const auto& [sz, lines] : all) {
    const auto u = lines.find(key("union", 0));
    if (u == lines.end()) continue;
    const double a0 = u->second.area;
    for (const auto& [k, l] : lines)
      std::printf("%zu %s %.3f %+.3e %zu %zu %zu\n", sz, k.c_str(), l.area, (l.area - a0) / a0, l.plans, l.holes,
                  l.vertices);
    for (const double d : {0.1, 0.5}) {
      const auto o = lines.find(key("close", d));
      const auto g = lines.find(key("geos_close", d));
      if (o == lines.end() || g == lines.end()) continue;
      std::printf("%zu closing D=%g: area ours - GEOS = %+.4f m2 (%+.2e of the area; added by the closing: ours "
                  "%.3f m2, GEOS %.3f m2), plans ours %zu GEOS %zu, holes ours %zu GEOS %zu\n",
                  sz, d, o->second.area - g->second.area, (o->second.area - g->second.area) / a0, o->second.area - a0,
                  g->second.area - a0, o->second.plans, g->second.plans, o->second.holes, g->second.holes);
    }
  }
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 10000, geos_max = 100000;
  std::string op = "union", matrix;
  double d = 0;
  int runs = 0, threads = 0, geos_runs_big = 1;
  std::uint64_t seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--n") n = std::strtoull(next(), nullptr, 10);
    else if (a == "--op") op = next();
    else if (a == "--d") d = std::strtod(next(), nullptr);
    else if (a == "--runs") runs = std::atoi(next());
    else if (a == "--seed") seed = std::strtoull(next(), nullptr, 10);
    else if (a == "--threads") threads = std::atoi(next());
    else if (a == "--matrix") matrix = next();
    else if (a == "--geos-max") geos_max = std::strtoull(next(), nullptr, 10);
    else if (a == "--geos-runs-big") geos_runs_big = std::atoi(next());
    else {
      std::fprintf(stderr,
                   "usage: %s --n N --op union|close|snap|simplify|cfd|geos_union|geos_close|geos_snap|geos_simplify|"
                   "geos_cfd [--d D] [--runs R] [--seed S] [--threads T]\n"
                   "       %s --matrix \"10000 100000\" [--geos-max N] [--runs R] [--geos-runs-big R] [--seed S] "
                   "[--threads T]\n",
                   argv[0], argv[0]);
      return 2;
    }
  }
  if (!matrix.empty()) return run_matrix(matrix, geos_max, runs, geos_runs_big, seed, threads);
  if ((op == "close" || op == "geos_close") && !(d > 0)) {
    std::fprintf(stderr, "--op %s needs --d D > 0\n", op.c_str());
    return 2;
  }
  return run_one(n, op, d, runs > 0 ? runs : 5, seed, threads);
}

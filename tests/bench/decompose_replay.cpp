// SPDX-License-Identifier: MIT
// Footprints per second by surface decomposition (issue 5) on meshes from a dump written by
// `decompose_bench --dump FILE`, so the figure can be taken on machines without the GIS libraries.
// Links only the decomposition (and the union engine for the shadow fallback; where that is not
// built, decompose_replay_no_union.cpp stands in and says so, and meshes that would take the shadow
// give other results: their count is printed).
//
// Usage: decompose_replay DUMP [--threads N] [--by-size]
//   one thread: per set, the median of >= 5 passes over >= 0.5 s, as decompose_bench times it;
//   --by-size: every mesh timed on its own (median of 5 samples of >= 20 us each), pooled over the
//   sets by size (vertex references): the cost per building grows with its size, so a set's mean
//   says as much about its size mix as about the speed;
//   --threads N: N threads decompose the same set at once for ~1 s each; per-thread throughput
//   (the per-core figure with every core busy) and the total.
// The result hash printed per set is decompose_hash(): equal to what decompose_bench --dump
// printed for the same dump when this machine computed the same footprints bit for bit.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.h"
#include "decompose_dump.h"

namespace {
using namespace groundplan;
using Clock = std::chrono::steady_clock;

/// Median seconds of one pass over the meshes.
double median_seconds(const std::vector<Mesh>& ms) {
  std::size_t sink = 0;
  const double sec = bench::median_seconds([&] {
    for (const Mesh& m : ms) sink += footprint::decompose_footprint(m).polygons.size();
  });
  return sec + (sink == 0xFFFFFFFF);  // keeps the work observable
}
/// Seconds per decomposition of m: median of 5 samples, each >= 20 us of repeated calls.
double seconds_per_call(const Mesh& m) {
  std::size_t sink = 0;
  int reps = 1;
  for (;;) {
    const auto t0 = Clock::now();
    for (int r = 0; r < reps; ++r) sink += footprint::decompose_footprint(m).polygons.size();
    if (std::chrono::duration<double>(Clock::now() - t0).count() >= 20e-6 || reps >= (1 << 20)) break;
    reps *= 2;
  }
  double t[5];
  for (double& v : t) {
    const auto t0 = Clock::now();
    for (int r = 0; r < reps; ++r) sink += footprint::decompose_footprint(m).polygons.size();
    v = std::chrono::duration<double>(Clock::now() - t0).count() / reps;
  }
  std::sort(t, t + 5);
  return t[2] + (sink == 0xFFFFFFFF);
}

void print_by_size(const std::vector<bench::MeshSet>& sets) {
  struct Class {
    std::size_t lo, hi;
    std::vector<double> us;
    double refs = 0, sec = 0;
  };
  std::vector<Class> cls{{0, 30, {}}, {31, 60, {}}, {61, 120, {}}, {121, 250, {}}, {251, 1000, {}}, {1001, SIZE_MAX, {}}};
  for (const bench::MeshSet& s : sets)
    for (const Mesh& m : s.meshes) {
      const std::size_t refs = m.indices.size();
      for (Class& c : cls)
        if (refs >= c.lo && refs <= c.hi) {
          const double sec = seconds_per_call(m);
          c.us.push_back(1e6 * sec);
          c.refs += refs;
          c.sec += sec;
        }
    }
  std::printf("-- by size, every set pooled (vertex references per building; one thread, each mesh timed alone)\n");
  std::printf("%-14s %6s %10s %12s %14s %12s\n", "refs", "bldg", "median us", "bldg/s", "bldg/s (mean)", "ns/ref");
  for (Class& c : cls) {
    if (c.us.empty()) continue;
    std::sort(c.us.begin(), c.us.end());
    const double med = c.us[c.us.size() / 2];
    char range[32];
    if (c.hi == SIZE_MAX) std::snprintf(range, sizeof range, "> %zu", c.lo - 1);
    else std::snprintf(range, sizeof range, "%zu-%zu", c.lo, c.hi);
    std::printf("%-14s %6zu %10.2f %12.0f %14.0f %12.1f\n", range, c.us.size(), med, 1e6 / med, c.us.size() / c.sec,
                1e9 * c.sec / c.refs);
  }
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: decompose_replay DUMP [--threads N]\n");
    return 2;
  }
  int threads = 0;
  bool by_size = false;
  for (int i = 2; i < argc; ++i) {
    if (std::string(argv[i]) == "--threads" && i + 1 < argc) threads = std::max(1, std::atoi(argv[i + 1]));
    if (std::string(argv[i]) == "--by-size") by_size = true;
  }
  std::vector<bench::MeshSet> sets;
  if (!bench::read_mesh_sets(argv[1], sets)) {
    std::fprintf(stderr, "%s: not a mesh dump of this version, or cut short\n", argv[1]);
    return 1;
  }
  for (const bench::MeshSet& s : sets) {
    std::size_t shadow = 0, faces = 0;
    for (const Mesh& m : s.meshes) shadow += footprint::decompose_footprint(m).stats.shadow, faces += m.faces.size();
    const double n = static_cast<double>(s.meshes.size());
    const double sec = median_seconds(s.meshes);
    std::printf("%-58s %6zu bldg %7.1f faces/bldg  decompose %9.0f bldg/s (%7.2f us)  shadow %zu  result hash %016llx\n",
                s.name.c_str(), s.meshes.size(), faces / n, n / sec, 1e6 * sec / n, shadow,
                static_cast<unsigned long long>(bench::decompose_hash(s.meshes)));
  }
  if (by_size) print_by_size(sets);
  if (threads > 0) {
    std::printf("-- %d threads at once, each decomposing the whole set repeatedly for ~1 s\n", threads);
    for (const bench::MeshSet& s : sets) {
      std::vector<double> rate(threads);
      std::atomic<int> ready{0};
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
          ++ready;
          while (ready.load() < threads) std::this_thread::yield();
          std::size_t done = 0, sink = 0;
          const auto t0 = Clock::now();
          double sec = 0;
          while (sec < 1.0) {
            for (const Mesh& m : s.meshes) sink += footprint::decompose_footprint(m).polygons.size();
            done += s.meshes.size();
            sec = std::chrono::duration<double>(Clock::now() - t0).count();
          }
          rate[t] = done / sec + (sink == 0xFFFFFFFF);
        });
      for (auto& th : pool) th.join();
      std::vector<double> r = rate;
      std::sort(r.begin(), r.end());
      double total = 0;
      for (double v : r) total += v;
      std::printf("%-58s per thread median %9.0f bldg/s [min %9.0f, max %9.0f]  total %10.0f bldg/s\n", s.name.c_str(),
                  r[r.size() / 2], r.front(), r.back(), total);
    }
  }
  return 0;
}

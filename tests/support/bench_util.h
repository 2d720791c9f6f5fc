// SPDX-License-Identifier: MIT
#pragma once
// Process CPU time, peak memory and repeated timing for the benchmarks in tests/bench.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace groundplan::bench {

/// User + system CPU seconds of this process so far.
inline double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// Peak resident set size of this process so far, MiB.
inline double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

/// Median wall seconds of one call of f, over >= 0.5 s of calls (at least 5).
template <class F>
double median_seconds(F&& f) {
  std::vector<double> t;
  double spent = 0;
  while (spent < 0.5 || t.size() < 5) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    spent += t.back();
  }
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

}  // namespace groundplan::bench

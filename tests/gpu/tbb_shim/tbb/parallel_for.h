// SPDX-License-Identifier: MIT
#pragma once
// Serial stand-in for the two oneTBB calls of core/src/blocks (tests/gpu/run_on_gpu.sh uses it only
// on a GPU machine without libtbb-dev; the results are the same, the CPU timings are one core's).
#include <cstddef>

namespace tbb {
template <class T>
struct blocked_range {
  blocked_range(T b, T e) : b_(b), e_(e) {}
  T begin() const { return b_; }
  T end() const { return e_; }
  T b_, e_;
};
template <class R, class F>
void parallel_for(const R& r, const F& f) {
  f(r);
}
}  // namespace tbb

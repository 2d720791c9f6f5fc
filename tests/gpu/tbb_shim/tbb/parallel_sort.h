// SPDX-License-Identifier: MIT
#pragma once
// Serial stand-in (see parallel_for.h).
#include <algorithm>

namespace tbb {
template <class It>
void parallel_sort(It b, It e) {
  std::sort(b, e);
}
}  // namespace tbb

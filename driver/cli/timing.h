// SPDX-License-Identifier: MIT
#pragma once
// Wall-clock seconds for the CLI's --stats and summary lines.
#include <chrono>

namespace groundplan::cli {

using clock = std::chrono::steady_clock;

inline double seconds_since(clock::time_point t0) { return std::chrono::duration<double>(clock::now() - t0).count(); }

}  // namespace groundplan::cli

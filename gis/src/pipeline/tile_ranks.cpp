// SPDX-License-Identifier: MIT
#include "pipeline/tile_ranks.h"

#include <groundplan/error.h>

#include <algorithm>
#include <numeric>

namespace groundplan::gis::detail {

std::vector<std::size_t> split_by_bytes(const std::vector<std::uint64_t>& sizes, int ranks, std::size_t first_free) {
  const std::size_t n = sizes.size();
  first_free = std::min(first_free, n);
  std::vector<std::size_t> bounds(static_cast<std::size_t>(ranks) + 1, n);
  bounds[0] = 0;
  // Every file weighs its bytes, and at least 1, so that empty files still spread.
  std::vector<double> before(n + 1, 0);
  for (std::size_t f = 0; f < n; ++f) before[f + 1] = before[f] + static_cast<double>(std::max<std::uint64_t>(sizes[f], 1));
  const double total = before[n];
  for (int r = 1; r < ranks; ++r) {
    // The first file whose start lies at or past r/ranks of the bytes begins rank r's run.
    const double target = total * r / ranks;
    std::size_t b = static_cast<std::size_t>(std::lower_bound(before.begin(), before.begin() + static_cast<std::ptrdiff_t>(n), target) - before.begin());
    // the nearer of the two file boundaries around the target
    if (b > 0 && target - before[b - 1] < before[b] - target) --b;
    // Every rank at least one file where there are files enough (an idle rank is a core lost), rank 0 its first ones.
    const std::size_t prev = bounds[static_cast<std::size_t>(r) - 1];
    const std::size_t lo = std::max(prev + 1, first_free), hi = n - std::min(n, static_cast<std::size_t>(ranks - r));
    if (lo <= hi)
      b = std::clamp(b, lo, hi);
    else
      b = std::max({b, prev, first_free});
    bounds[static_cast<std::size_t>(r)] = std::min(b, n);
  }
  return bounds;
}

void Packer::str(const std::string& s) {
  put(static_cast<std::uint64_t>(s.size()));
  bytes.insert(bytes.end(), s.begin(), s.end());
}

void Packer::problems(const std::vector<Problem>& list) {
  put(static_cast<std::uint64_t>(list.size()));
  for (const Problem& p : list) {
    str(p.source_id);
    str(p.file);
    str(p.stage);
    str(p.code);
    str(p.reason);
  }
}

void Unpacker::problems(std::vector<Problem>& out) {
  const auto n = get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) {
    Problem p;
    p.source_id = str();
    p.file = str();
    p.stage = str();
    p.code = str();
    p.reason = str();
    out.push_back(std::move(p));
  }
}

}  // namespace groundplan::gis::detail

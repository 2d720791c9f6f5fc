// SPDX-License-Identifier: MIT
#pragma once
// Footprints decoded from fuzz bytes, shared by the union and level-of-detail targets. Byte 0 picks
// the coordinate mode (small integer grid: shared vertices, collinear edges, touching; a fine grid at
// a large offset; half-integers; inexact sevenths), then per footprint one byte of vertex count and a
// hole flag, and two bytes per vertex. At most 12 footprints.
#include <groundplan/types.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace groundplan::fuzz {

struct Decoder {
  const std::uint8_t* p;
  const std::uint8_t* end;
  bool more() const { return p < end; }
  std::uint8_t byte() { return p < end ? *p++ : 0; }
};

inline double coord(std::uint8_t v, int mode, bool is_x) {
  switch (mode) {
    case 0: return static_cast<double>(v % 16);                             // tiny grid: degeneracies
    case 1: return (is_x ? 500000.0 : 5400000.0) + static_cast<double>(v) * 0.125;  // offset, dyadic
    case 2: return static_cast<double>(v) * 0.5;
    default: return static_cast<double>(v) / 7.0;                           // inexact
  }
}

/// The footprints, and where decoding stopped (for targets that read parameters after them).
inline std::vector<Footprint> decode_footprints(const std::uint8_t* data, std::size_t size,
                                                const std::uint8_t** rest = nullptr) {
  Decoder d{data, data + size};
  const int mode = d.byte() % 4;
  std::vector<Footprint> fps;
  while (d.more() && fps.size() < 12) {
    const std::uint8_t head = d.byte();
    const std::size_t n = 3 + head % 14;
    const bool with_hole = head & 0x80;
    Footprint f;
    f.source_id = std::to_string(fps.size());
    f.source_id.insert(f.source_id.begin(), 'f');  // not "f" + ...: GCC 12 warns falsely (-Wrestrict)
    Polygon poly;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint8_t x = d.byte(), y = d.byte();
      poly.outer.push_back({coord(x, mode, true), coord(y, mode, false)});
    }
    if (with_hole)
      for (std::size_t i = 0; i < 3u + static_cast<std::size_t>((head >> 4) % 4); ++i) {
        const std::uint8_t x = d.byte(), y = d.byte();
        if (poly.holes.empty()) poly.holes.emplace_back();
        poly.holes.back().push_back({coord(x, mode, true), coord(y, mode, false)});
      }
    f.polygons.push_back(std::move(poly));
    fps.push_back(std::move(f));
  }
  if (rest) *rest = d.p;
  return fps;
}

}  // namespace groundplan::fuzz

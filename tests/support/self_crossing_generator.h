// SPDX-License-Identifier: MIT
#pragma once
// Self-crossing footprints (issue 20): bow-ties, figure-eights, rings that retrace part of an edge,
// spikes in and out, rings through their own vertex, pentagrams, with coordinates in sevenths or
// elevenths (inexact in binary, so every crossing the union computes is rounded), next to ordinary
// overlapping quads. Each ring's region is its even-odd region, which is what GEOS MakeValid
// returns for these shapes (no ring traces one closed loop twice). Seeded, for property tests.
#include <groundplan/types.h>

#include <cstdint>
#include <random>
#include <vector>

namespace groundplan::testing {

/// A few self-crossing footprints and quads, overlapping each other, within ~3 m of (x0, y0).
std::vector<Footprint> self_crossing_case(std::mt19937_64& rng, double x0 = 0, double y0 = 0);

/// About n footprints: self_crossing_case on a grid of cells ~4 m apart (neighbours may touch or
/// overlap), source ids "sc<k>". offset adds to every coordinate (city coordinates: 5e5, 5.4e6).
std::vector<Footprint> self_crossing_city(std::size_t n, std::uint64_t seed, double offset_x = 0,
                                          double offset_y = 0);

}  // namespace groundplan::testing

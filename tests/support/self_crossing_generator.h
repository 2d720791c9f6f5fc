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

/// Lattice units a metre common to both denominators (7 and 11): every vertex is a whole number of them.
constexpr int kCommonDen = 77;

/// A few self-crossing footprints and quads, overlapping each other, within ~3 m of (x0, y0).
/// With `on_lattice`, the same footprints are appended there in kCommonDen units a metre, as exact
/// integers (x0 and y0 must then be whole metres). Sevenths in binary move three lines through one
/// lattice point a few ulps apart, so floating-point noding (GEOS MakeValid's) can decide such a point
/// inconsistently; on the lattice GEOS meets those points exactly. The reference the tests use.
std::vector<Footprint> self_crossing_case(std::mt19937_64& rng, double x0 = 0, double y0 = 0,
                                          std::vector<Footprint>* on_lattice = nullptr);

/// About n footprints: self_crossing_case on a grid of cells ~4 m apart (neighbours may touch or
/// overlap), source ids "sc<k>". offset adds to every coordinate (city coordinates: 5e5, 5.4e6; whole
/// metres when `on_lattice` is given, which receives the same city on the lattice, same source ids).
std::vector<Footprint> self_crossing_city(std::size_t n, std::uint64_t seed, double offset_x = 0,
                                          double offset_y = 0, std::vector<Footprint>* on_lattice = nullptr);

}  // namespace groundplan::testing

// SPDX-License-Identifier: MIT
#pragma once
// Seeded random footprints per degenerate family (issue 3 property tests, and the benchmark city).
#include <groundplan/types.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace groundplan::testing {

using Rng = std::mt19937_64;

enum class Family {
  PartyWalls,        // rows of houses sharing exact walls, some deeper/shallower (partial walls),
                     // rotated exactly (dyadic coordinates, integer rotation matrix)
  CollinearOverlap,  // lattice rectangles overlapping along collinear edges
  VertexTouch,       // squares and triangles touching at single points
  Nested,            // polygons inside polygons, holes filled by others
  Duplicates,        // identical copies, other start vertex, reversed orientation
  BowTies,           // self-intersecting rings
  RepeatedPoints,    // consecutive duplicate vertices
  Slivers,           // zero-area spikes and degenerate polygons
  LargeOffsets,      // coordinates 1e5..1e7 with millimetre features
  RotatedBlocks,     // rotated rectangles with inexact coordinates
  Holes,             // polygons with courtyards, some holes touching
  RandomOverlap,     // random star-shaped polygons overlapping
  NearCollinear,     // party walls rotated by any angle: walls collinear only up to rounding, so
                     // gaps and overlaps far below one ulp (GEOS may snap them; see the test)
  DenseRings,        // isochrone-like rings of 200 to 3000 vertices overlapping one another (issue 20)
  VertexOnEdge,      // a vertex of one polygon put on another's inexact edge (a + t (b - a) in doubles,
                     // so within rounding of it), from outside and from inside (issue 20)
  CityFineFeatures,  // city coordinates (1e6..1e7 m) with gaps, slivers and holes 1 mm to 1 nm wide
                     // (issue 20)
};
const char* family_name(Family f);
constexpr Family kAllFamilies[] = {Family::PartyWalls,   Family::CollinearOverlap, Family::VertexTouch,
                                   Family::Nested,       Family::Duplicates,       Family::BowTies,
                                   Family::RepeatedPoints, Family::Slivers,        Family::LargeOffsets,
                                   Family::RotatedBlocks, Family::Holes,           Family::RandomOverlap,
                                   Family::NearCollinear, Family::DenseRings,      Family::VertexOnEdge,
                                   Family::CityFineFeatures};

/// One random case of the family (a few to a few dozen footprints).
std::vector<Footprint> generate_case(Family f, Rng& rng);

/// A synthetic city of n footprints (benchmark): blocks of row houses with exact party walls,
/// courtyards, overlapping wings, rotated blocks, detached houses; origin at (500000, 5400000).
/// coverage = true leaves out everything that overlaps and every partial wall, so that the result
/// is a valid polygonal coverage (for GEOSCoverageUnion).
std::vector<Footprint> synthetic_city(std::size_t n, std::uint64_t seed, bool coverage = false);

}  // namespace groundplan::testing

// SPDX-License-Identifier: MIT
#pragma once
// Generated buildings whose true footprint is known (issue 21), modelled the way SketchUp / Google
// Earth models are: plain polygons without semantics (SurfaceKind::Unknown, lod 255), parts that rest
// on each other without sharing edges, open bottoms. Every family comes written three ways (convex
// polygons; the same fanned into triangles over shared corners; a triangle soup: triangles shuffled,
// randomly flipped, corners jittered well inside the weld tolerance) and with and without a floor
// (the faces that lie on the ground). The true footprint is the paper's (§4): where the walls meet
// the ground, so eaves, roof slabs, cantilevered storeys and balconies never count.
#include <groundplan/mesh.h>

#include <string>
#include <vector>

namespace groundplan::test {

enum class Writing { Polygons, Triangles, Soup };

struct KnownFootprint {
  std::string family;        // "slab_roof", ...
  std::string name;          // family + "_" + writing + ("_floor" | "_open"): a gtest-safe name
  Writing writing = Writing::Polygons;
  bool floor = false;        // the ground-level faces are written
  Mesh mesh;
  std::string true_wkt;      // the true footprint, (Multi)Polygon WKT
  double true_area_m2 = 0;
  double shadow_area_m2 = 0; // area of the vertical projection of the whole model (what a shadow gives)
};

/// The families, in order: eaves_open, eaves_soffit, slab_roof, cantilever, balcony, stepped_ground,
/// stacked_boxes, stacked_overhang, stacked_corner, disconnected, and one closed mesh each: plinth, podium,
/// podium_corner, terraces, multi_tower, arcade.
std::vector<std::string> known_footprint_families();

/// Every family x writing x floor, deterministic (fixed seeds).
std::vector<KnownFootprint> known_footprints();

}  // namespace groundplan::test

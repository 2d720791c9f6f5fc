// SPDX-License-Identifier: MIT
#pragma once
// Level of detail for simulation (issue 9): snap, close gaps, fill sub-pixel holes, simplify, drop
// small holes and plans. Everything here is opt-in: with default LodParams the plans are the exact
// union (build_ground_plans). Every step keeps the plans valid and non-overlapping, and says what it
// removed (LodStats, and Problems with stage "lod"): nothing changes silently.
// docs/level_of_detail.md says what each step guarantees and how the values of --preset cfd were chosen.
#include <groundplan/ground_plans.h>
#include <groundplan/progress.h>
#include <groundplan/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace groundplan {

struct LodParams {
  double snap_m = 0;            // --snap D: vertices and edges closer than D become shared, before the union (0 = off)
  double close_gaps_m = 0;      // --close-gaps D: gaps and cavities narrower than D close (closing by D/2, mitre joins)
  double min_hole_area_m2 = 0;  // --min-hole-area A: holes below A m² are filled (0 = off)
  double min_area_m2 = 0;       // --min-area A: plans below A m² are dropped, their buildings reported (0 = off)
  double simplify_m = 0;        // --simplify T: topology-preserving simplification within T metres (0 = off)
  bool raster = false;          // --resolution-mode raster: the paper's level of detail; holes that hold no whole
                                // pixel of the blocks raster (UnionParams::resolution_m) are filled
  bool any() const {
    return snap_m > 0 || close_gaps_m > 0 || min_hole_area_m2 > 0 || min_area_m2 > 0 || simplify_m > 0 || raster;
  }
};

/// What each step did (for --stats, the docs' report and the tests).
struct LodStats {
  // --snap
  std::size_t snap_vertices_moved = 0;     // input vertices moved onto another vertex
  std::size_t snap_vertices_inserted = 0;  // vertices inserted into another ring's edge
  std::size_t snap_rings_collapsed = 0;    // rings left with fewer than 3 distinct vertices (dropped)
  // --close-gaps
  std::size_t close_plans_before = 0, close_plans_after = 0;
  double close_area_added_m2 = 0;
  std::size_t close_plans_failed = 0;      // plans left unclosed because a union inside the closing failed
  // --resolution-mode raster
  std::size_t raster_holes_filled = 0;
  double raster_pixel_m = 0;               // the pixel size used (the automatic one when resolution_m = 0)
  // --simplify
  std::size_t simplify_vertices_before = 0, simplify_vertices_after = 0;
  // --min-hole-area, --min-area
  std::size_t holes_filled = 0;
  double holes_filled_area_m2 = 0;
  std::size_t plans_dropped = 0;
  double plans_dropped_area_m2 = 0;
  // time per step, seconds
  double snap_s = 0, close_s = 0, raster_s = 0, simplify_s = 0, filter_s = 0;
};

/// --snap: a copy of `footprints` in which every vertex within `tolerance_m` of an earlier kept
/// vertex (footprint order, then ring order) moves onto it (no chaining: kept vertices are more than
/// `tolerance_m` apart), then every kept vertex within `tolerance_m` of an edge of another ring is
/// inserted into that edge. Almost-touching walls then share their vertices exactly, so the exact
/// union joins them. Each vertex moves at most `tolerance_m`; an edge at most 2 `tolerance_m` (its ends move, then a
/// vertex within `tolerance_m` of the moved edge is inserted).
/// Consecutive repeated points are removed; a ring left with < 3 points is dropped (counted).
std::vector<Footprint> snap_footprints(const std::vector<Footprint>& footprints, double tolerance_m,
                                       LodStats* stats = nullptr);

/// --close-gaps: the morphological closing of the plans by width_m / 2 with mitre joins (dilate, then
/// erode), computed with the exact union engine, then reconciled with the input so that walls not
/// part of a gap keep their vertices. Plans that the closing joins become one plan (members merged).
/// The result contains the input plans.
std::vector<GroundPlan> close_gaps(const std::vector<GroundPlan>& plans, double width_m,
                                   const UnionParams& union_params, LodStats* stats = nullptr);

/// --simplify: Douglas-Peucker within tolerance_m on every ring, refusing any shortcut that would
/// cross another edge (of any ring of any plan) or sweep over another ring's vertex; points where
/// rings touch stay. Rings keep at least 3 vertices. Plans stay valid and do not start to overlap.
std::vector<GroundPlan> simplify_plans(const std::vector<GroundPlan>& plans, double tolerance_m,
                                       LodStats* stats = nullptr);

/// The whole union stage with a level of detail: snap -> exact union -> close gaps -> raster holes ->
/// simplify -> min hole area -> min area. With params.any() false this is build_ground_plans.
/// Filled holes and dropped plans become Problems (stage "lod"; a dropped plan: one per member
/// building, so that every building is still in a plan or named by a problem).
std::vector<GroundPlan> build_ground_plans(const std::vector<Footprint>& footprints, const UnionParams& union_params,
                                           const LodParams& lod, std::vector<Problem>& problems,
                                           const Progress& progress = {}, LodStats* stats = nullptr);

/// Area of a polygon with holes (m², outer minus holes), computed about a local origin.
double polygon_area(const Polygon& polygon);

}  // namespace groundplan

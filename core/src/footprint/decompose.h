// SPDX-License-Identifier: MIT
#pragma once
// Footprints by surface decomposition (paper §4, issue 5): a mesh without trusted semantics is cut
// into floor, ceiling and wall patches; a footprint is a closed lower boundary of the walls that is a
// local minimum (the walls rise from every edge of it), projected to 2D.
//
// Input: any groundplan::Mesh (polygon faces with holes, triangle soup, duplicated vertices,
// inconsistent facet orientation, non-manifold edges, T-junctions, several disconnected parts).
// SurfaceKind is ignored except that lod0 outlines (FootPrint, RoofEdge) are not surfaces of the
// solid and are skipped. Coordinates: x, y metric (working CRS), z up, metres.
//
// Output: polygons in the mesh's x, y with outer rings counter-clockwise and holes clockwise, closed
// (no repeated closing vertex), no NaN. The polygons never overlap: loops of different parts that do
// are united (the project's union engine, issue 21). Never throws for bad geometry: an empty result
// and the stats say why.
//
// Rules beyond the paper, in order of use: (1) the lower boundary is chained over welded 3D vertices;
// (2) chains that do not close are chained again in plan view (endpoints within weld_tolerance_m in
// x, y are one), so a wall bottom stepping up or down a terraced site at a vertical edge still closes;
// (3) where the loops miss the ground-level lower boundary, the shadow (DecomposeParams::shadow_fallback);
// (4) parts that touch without sharing edges meet where an edge of one lies in a face of the other
// (decompose/contacts.cpp: slabs laid on walls, boxes set on roofs, balconies against walls).
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace groundplan::footprint {

struct DecomposeParams {
  /// Proxy-plane tolerance (paper §4, VSA proxy): a facet whose normal is within this angle of the
  /// vertical proxy normal is a floor (normal down) or ceiling (normal up) facet; the rest are walls.
  /// Floors that follow terrain steeper than this count as walls and break the lower boundary: raise
  /// it for hilly cities (ceilings and roofs do not care: their wall edges are upper boundaries).
  double proxy_tolerance_deg = 20.0;
  /// Vertices closer than this are one vertex (recovers connectivity of triangle soup and of
  /// polygons written with their own copies of shared corners); also the distance within which a
  /// vertex lying on another face's edge splits it (T-junctions). Metres.
  double weld_tolerance_m = 1e-3;
  /// Loops whose projected area is below this are dropped (slivers, vertical faces seen edge-on). m².
  double min_loop_area_m2 = 1e-6;
  /// When the lower boundary closes no loop, or a tenth or more of it (plan length) stays in open
  /// chains outside every loop and no higher than the loops reach (models that are not watertight:
  /// SketchUp/COLLADA exports with gaps, walls standing on roofs they share no edge with), take the
  /// mesh's shadow instead: the exact union of the vertical projections of its facets, rings under
  /// 0.01 m² dropped. It covers overhangs too, so it is only the last resort; stats.shadow says so.
  bool shadow_fallback = true;
};

enum class PatchKind : std::uint8_t { Floor, Ceiling, Wall };

/// The decomposition itself (for tests and diagnostics; the footprint does not need it).
struct SurfaceDecomposition {
  std::vector<std::int32_t> face_patch;   // per mesh face: patch index, -1 for skipped/degenerate faces
  std::vector<PatchKind> patch_kind;      // per patch
  std::vector<double> patch_z;            // per patch: proxy-plane height (area-weighted mean z)
  std::vector<double> patch_area_m2;      // per patch: facet area
};

struct DecomposeStats {
  std::size_t faces_used = 0;             // faces with a usable outer ring
  std::size_t duplicate_faces = 0;        // copies of a face dropped (same welded outer ring)
  std::size_t vertices_welded = 0;        // distinct vertices after welding
  std::size_t t_junction_splits = 0;      // edges split at a vertex lying on them
  std::size_t nonmanifold_edges = 0;      // edges with more than two facets
  std::size_t components = 0;             // parts connected through manifold edges
  std::size_t unoriented_components = 0;  // parts whose outside could not be told (no volume)
  std::size_t flipped_faces = 0;          // faces whose orientation was turned outward
  std::size_t footprint_edges = 0;        // lower-boundary edges of the walls (local minima)
  std::size_t loops = 0;                  // closed lower-boundary loops
  std::size_t open_chains = 0;            // lower-boundary chains that did not close (not footprints)
  std::size_t holes = 0;                  // loops that became holes
  std::size_t dropped_loops = 0;          // loops below min area, or holes inside no outer ring
  std::size_t chained_in_plan = 0;        // chains closed only when joined in plan view (stepped bottoms)
  std::size_t contacts = 0;               // edges found lying in another part's face (parts laid on each other)
  bool united = false;                    // the loops overlapped and were united into one footprint
  double lower_boundary_m = 0;           // plan length of the footprint edges (set when chains stay open)
  double open_outside_m = 0;              // of which in open chains outside every loop, no higher than them
  bool closed_in_plan = false;            // the loops missed; the lower boundary closed in plan instead
  double plan_kept_m = 0;                 // of the lower boundary, plan length left once dangling chains went
  double plan_gap_m = 0;                  // ends this close in plan were joined
  double plan_pruned_outside_m = 0;       // pruned (dangling) lower boundary outside the faces closed in plan
  bool shadow = false;                    // the polygons are the shadow (shadow_fallback), not loops
};

struct DecomposeResult {
  std::vector<Polygon> polygons;
  DecomposeStats stats;
};

/// Footprint polygons of `mesh` by surface decomposition. Fills `decomposition` when given.
/// Thread-safe (per-thread scratch buffers).
DecomposeResult decompose_footprint(const Mesh& mesh, const DecomposeParams& params = {},
                                    SurfaceDecomposition* decomposition = nullptr);

}  // namespace groundplan::footprint

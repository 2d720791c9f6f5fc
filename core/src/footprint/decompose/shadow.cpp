// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 8, the shadow (last resort).
//
//  8. When no loop closes, or a tenth or more of the lower boundary (plan length) lies in open chains
//     outside every loop and no higher than the loops (a model that is not watertight: SketchUp /
//     COLLADA exports whose walls stop short of each other or stand on roofs they share no edge
//     with), the loops do not say where the building stands: the footprint is its shadow, the exact
//     union of the facets' vertical projections (DecomposeParams::shadow_fallback; issue 5, Macky).
#include "footprint/decompose.h"
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

/// Shadow rings (outer or hole) smaller than this are dropped (rule 3). m².
constexpr double kShadowMinRing_m2 = 0.01;

/// Rule 3: the loops miss where the building stands (a mesh full of gaps, walls
/// on roofs they share no edge with, faces that end short of each other: SketchUp exports). The
/// shadow, the union of every used facet's vertical projection, is what is certain about where
/// the building stands: it is the footprint wherever the building does not overhang its base.
/// The union is the project's exact engine on one footprint; should it fail, the projected facets
/// go out as they are (overlapping polygons, which the pipeline's union merges anyway).
void Decomposer::make_shadow(std::vector<Polygon>& out) {
  Footprint fp;
  for (std::uint32_t f = 0; f < ws_.faces.size(); ++f) {
    // Walls too: one leaning by a hair bridges a modelling gap of millimetres (an annex drawn a
    // hair off the hall); the slivers they leave elsewhere are dropped below.
    if (ws_.faces[f].cls == kSkipped) continue;
    const MeshFace& mf = m_.faces[f];
    Polygon poly;
    for (std::uint32_t r = mf.first_ring; r < mf.first_ring + mf.ring_count; ++r) {
      if (!welded_ring(r) || ws_.ring_tmp.size() < 3) continue;
      Ring ring;
      ring.reserve(ws_.ring_tmp.size());
      double a = 0;
      for (std::size_t i = 0; i < ws_.ring_tmp.size(); ++i) {
        const V3& p = ws_.wpos[ws_.ring_tmp[i]];
        const V3& q = ws_.wpos[ws_.ring_tmp[i + 1 < ws_.ring_tmp.size() ? i + 1 : 0]];
        a += p.x * q.y - q.x * p.y;
        ring.push_back(Point2{p.x + o_.x, p.y + o_.y});
      }
      if (!(std::fabs(a / 2) >= p_.min_loop_area_m2)) {
        if (r == mf.first_ring) break;  // seen edge-on: no area, its holes neither
        continue;
      }
      const bool outer = r == mf.first_ring;
      if ((a > 0) != outer) std::reverse(ring.begin(), ring.end());
      if (outer) {
        poly.outer = std::move(ring);
      } else {
        poly.holes.push_back(std::move(ring));
      }
    }
    if (!poly.outer.empty()) fp.polygons.push_back(std::move(poly));
  }
  if (fp.polygons.empty()) return;
  stats_->shadow = true;
  // Rings under kShadowMinRing_m2 are what walls leaning by a hair leave along their lines. Should
  // the union fail, the projected facets go out as they are (the pipeline's union merges them).
  out = std::move(fp.polygons);
  unite_polygons(out, kShadowMinRing_m2);
}

}  // namespace groundplan::footprint::detail

// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5). Stage 5, the lower boundary of the walls.
//
//  5. Lower boundary: an edge is a footprint edge when a wall facet rises from it (the in-plane
//     direction into the facet points up) and no wall facet continues below it: the paper's local
//     minimum, decided per edge, so it does not depend on floors being present, whole or holed.
//     Not where a ceiling meets it (paper: "except the ceiling boundaries": parapets, penthouses),
//     nor a floor patch from which a wall goes down elsewhere (a soffit: an upper storey wider than
//     the one below on every side would otherwise give its shadow). Edges of two wall facets that
//     rise from it on opposite sides (parts sharing a wall) cancel. Where the ground steps (a floor
//     that follows a slope, classification.cpp), the riser's top edge bounds the upper step.
#include "footprint/decompose/decomposer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

void Decomposer::collect_footprint_edges() {
  auto& cand = ws_.cand;
  cand.clear();
  const std::size_t ng = ws_.group_count.size();
  const std::uint32_t* cnt = ws_.group_count.data();
  const std::uint32_t* st = ws_.group_start.data();
  const std::uint32_t* mem = ws_.group_members.data();
  const HalfEdge* H = ws_.halfedges.data();
  const FaceInfo* F = ws_.faces.data();
  const std::uint8_t* hanging = ws_.hanging.data();
  const std::uint8_t* step = ws_.step_floor.data();
  for (std::size_t g = 0; g < ng; ++g) {
    if (ws_.on_roof[g]) continue;  // stands on another part's roof (contacts.cpp)
    const std::uint32_t s = st[g], c = cnt[g];
    int net = 0, net_down = 0;
    bool below = false, down = false, on_step = false;
    std::uint32_t comp = kNone, lo = 0, hi = 0;
    for (std::uint32_t i = 0; i < c; ++i) {
      const HalfEdge& h = H[mem[s + i]];
      const FaceInfo& fi = F[h.face];
      if (fi.cls == kCeiling || (fi.cls == kFloor && hanging[h.face])) {
        // A ceiling boundary (paper §4: "except the ceiling boundaries"): walls rising from a roof
        // (the inside of a parapet, a penthouse) stand on the building, not on the ground; so do
        // walls rising from a soffit.
        below = true;
        break;
      }
      if (fi.cls == kFloor) on_step |= step[h.face] != 0;
      if (fi.cls != kWall || h.up == 0) continue;
      // Outward orientation: the building lies left of the edge seen from above.
      const std::uint32_t from = fi.sign > 0 ? h.a : h.b;
      lo = std::min(h.a, h.b);
      hi = std::max(h.a, h.b);
      if (comp == kNone) comp = comp_of(h.face);
      if (h.up < 0) {
        // A wall going down: no local minimum, unless it is the riser below a step of the ground
        // (classification.cpp), whose top edge bounds the upper step. Seen from above, the wall's
        // top edge runs against its bottom edge, so the upper step (outside the riser) lies left.
        down = true;
        net_down += from == lo ? 1 : -1;
        continue;
      }
      net += from == lo ? 1 : -1;
    }
    if (below || (down && !on_step)) continue;
    net += net_down;
    if (net == 0) continue;
    for (int k = 0; k < std::abs(net); ++k) cand.push_back(net > 0 ? DirEdge{lo, hi, comp} : DirEdge{hi, lo, comp});
  }
  stats_->footprint_edges = cand.size();
}

}  // namespace groundplan::footprint::detail

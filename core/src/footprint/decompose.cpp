// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5).
//
// Pipeline per mesh, all on per-thread scratch buffers (issue 5 asks for >= 200k LoD2 buildings/s per
// core, i.e. a few microseconds each, so nothing here allocates once the buffers are warm, and hash
// tables are not even cleared: their slots carry a generation number, see GenTable):
// The stages, in order, each in its own file under decompose/ (see decompose/decomposer.h):
//  1. weld.cpp, 2. topology.cpp and t_junctions.cpp, 3. orientation.cpp, 4. classification.cpp,
//  4b. contacts.cpp, 5. lower_boundary.cpp, 6. loops.cpp, 7. polygons.cpp, 7b. unite.cpp, 7c. plan_faces.cpp
//  (when the loops miss: the lower boundary closed in plan), 8. shadow.cpp (last resort). This file runs them.
#include "footprint/decompose.h"

#include "footprint/decompose/decomposer.h"

#include <cmath>

namespace groundplan::footprint {
namespace detail {

Workspace& workspace() {
  thread_local Workspace ws;
  return ws;
}

DecomposeResult Decomposer::run(SurfaceDecomposition* dec) {
  DecomposeResult res;
  stats_ = &res.stats;
  if (!find_origin()) return res;
  build_faces();
  resolve_duplicates();
  if (stats_->faces_used == 0) return res;
  if (!ws_.dups.empty()) group_edges();  // else grouped in the ring pass, nothing dropped
  else finish_groups(ng_);
  if (split_t_junctions()) group_edges();
  orient();
  classify();
  find_hanging_floors();
  find_contacts();
  if (dec) fill_decomposition(*dec);
  collect_footprint_edges();
  chain_loops();
  make_polygons(res.polygons);
  if (p_.shadow_fallback && (res.polygons.empty() || open_outside_loops())) {
    res.polygons.clear();
    if (!close_in_plan(res.polygons)) make_shadow(res.polygons);
  } else {
    unite_loops(res.polygons);
  }
  return res;
}

bool Decomposer::find_origin() {
  for (const Point3& q : m_.vertices)
    if (std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z)) {
      o_ = {q.x, q.y, q.z};
      return true;
    }
  return false;
}

}  // namespace detail

DecomposeResult decompose_footprint(const Mesh& mesh, const DecomposeParams& params, SurfaceDecomposition* decomposition) {
  detail::Decomposer d(mesh, params, detail::workspace());
  return d.run(decomposition);
}

}  // namespace groundplan::footprint

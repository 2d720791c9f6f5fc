// SPDX-License-Identifier: MIT
// Stands in for the union engine where decompose_replay is built without it (a machine without
// MPFR): the decomposition's shadow fallback then gets an exception and, as it does whenever the
// union fails, returns the projected facets unmerged. decompose_replay prints how many meshes take
// the shadow, so a set whose figures this touches is known. Never linked into the project's builds.
#include <groundplan/ground_plans.h>

#include <stdexcept>

namespace groundplan {
std::vector<GroundPlan> build_ground_plans(const std::vector<Footprint>&, const UnionParams&, std::vector<Problem>&,
                                           const Progress&) {
  throw std::runtime_error("decompose_replay built without the union engine");
}
}  // namespace groundplan

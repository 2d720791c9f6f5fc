// SPDX-License-Identifier: MIT
// The CityGML reader on arbitrary bytes (issue 8). Expected outcomes: meshes, Problems, or an
// InputError naming the buffer; anything else (a crash, a sanitizer report, another exception, a
// mesh with non-finite vertices or indices out of range) is a finding.
#include "fuzz_entry.h"

#include <groundplan/error.h>
#include <groundplan/gis/citygml.h>

#include <cmath>
#include <string_view>

GROUNDPLAN_FUZZ_TARGET(citygml) {
  using namespace groundplan;
  gis::CityGmlOptions options;
  options.max_depth = 64;                 // reach the limit with small inputs too
  options.max_pending_buildings = 4;      // and the forward-xlink give-up path
  options.xlink_index_max_vertices = 64;  // and the look-aside eviction
  options.lod = size > 0 ? static_cast<int>(data[0] % 6) - 1 : -1;
  std::vector<Problem> problems;
  gis::SourceInfo info;
  auto check = [](Mesh&& m) {
    for (const Point3& p : m.vertices)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        groundplan_fuzz_fail("citygml", "a delivered mesh has a non-finite vertex");
    for (std::uint32_t i : m.indices)
      if (i >= m.vertices.size()) groundplan_fuzz_fail("citygml", "a mesh index is out of range");
    if (m.ring_offsets.empty() || m.ring_offsets.back() != m.indices.size())
      if (!(m.ring_offsets.empty() && m.indices.empty()))
        groundplan_fuzz_fail("citygml", "ring offsets do not end at the index count");
    if (m.source_id.empty()) groundplan_fuzz_fail("citygml", "a mesh without a source id");
  };
  try {
    gis::read_citygml_buffer(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.gml", options,
                             check, problems, info);
  } catch (const InputError&) {
  }
  for (const Problem& p : problems)
    if (p.file != "fuzz.gml" || p.code.empty() || p.reason.empty())
      groundplan_fuzz_fail("citygml", "a problem without file, code or reason");
  return 0;
}

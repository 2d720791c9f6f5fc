// SPDX-License-Identifier: MIT
// The CityGML reader on arbitrary bytes (issue 8). Expected outcomes: meshes, Problems, or an
// InputError naming the buffer; anything else (a crash, a sanitizer report, another exception, a
// mesh with non-finite vertices or indices out of range) is a finding. Issue 14: a document parsed
// in memory (pugixml, gis/src/xml/dom_events.h) must read exactly as expat streaming it reads it:
// every input taken in memory is read again streamed, and any difference in meshes, problems or
// the error is a finding.
#include "fuzz_entry.h"

#include <groundplan/error.h>
#include <groundplan/gis/citygml.h>

#include <cmath>
#include <cstring>
#include <string>
#include <string_view>

namespace {
/// Everything a reading gave, doubles by their bits.
struct Reading {
  std::string meshes, problems, error;
  groundplan::gis::SourceInfo info;
};

void add_bits(std::string& s, double v) {
  char b[sizeof v];
  std::memcpy(b, &v, sizeof v);
  s.append(b, sizeof v);
}

Reading read(std::string_view xml, const groundplan::gis::CityGmlOptions& options) {
  using namespace groundplan;
  Reading r;
  std::vector<Problem> problems;
  try {
    gis::read_citygml_buffer(xml, "fuzz.gml", options, [&](Mesh&& m) {
      r.meshes += m.source_id + '|' + m.parent_id + '|' + m.name + '|';
      add_bits(r.meshes, m.measured_height);
      for (const Point3& p : m.vertices) add_bits(r.meshes, p.x), add_bits(r.meshes, p.y), add_bits(r.meshes, p.z);
      for (std::uint32_t i : m.indices) r.meshes += std::to_string(i) + ',';
      for (std::uint32_t o : m.ring_offsets) r.meshes += std::to_string(o) + ';';
      for (const MeshFace& f : m.faces)
        r.meshes += std::to_string(f.first_ring) + ':' + std::to_string(f.ring_count) + ':' +
                    std::to_string(static_cast<int>(f.kind)) + ':' + std::to_string(f.lod) + '/';
      r.meshes += '\n';
    }, problems, r.info);
  } catch (const InputError& e) {
    r.error = e.what();
  }
  for (const Problem& p : problems) r.problems += p.source_id + '|' + p.code + '|' + p.reason + '\n';
  return r;
}
}  // namespace

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
  if (info.bytes > 0 && info.bytes_streamed == 0) {  // read in memory: streamed, it must read the same
    const std::string_view xml(reinterpret_cast<const char*>(data), size);
    const Reading in_memory = read(xml, options);
    gis::CityGmlOptions streamed = options;
    streamed.dom_max_bytes = 0;
    const Reading by_expat = read(xml, streamed);
    if (in_memory.meshes != by_expat.meshes) groundplan_fuzz_fail("citygml", "meshes differ in memory and streamed");
    if (in_memory.problems != by_expat.problems)
      groundplan_fuzz_fail("citygml", "problems differ in memory and streamed");
    if (in_memory.error != by_expat.error) groundplan_fuzz_fail("citygml", "errors differ in memory and streamed");
  }
  return 0;
}

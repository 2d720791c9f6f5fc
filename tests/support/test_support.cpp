// SPDX-License-Identifier: MIT
#include "test_support.h"

#include "test_config.h"

#include <groundplan/gis/geos_reference.h>

namespace groundplan::test {

std::string shared_data(const std::string& relative) { return std::string(GROUNDPLAN_SHARED_DATA_DIR) + "/" + relative; }
std::string sample_data(const std::string& relative) { return std::string(GROUNDPLAN_SAMPLE_DATA_DIR) + "/" + relative; }

std::vector<Footprint> footprints_from_wkt(const std::vector<std::string>& wkts) {
  std::vector<Footprint> out;
  for (std::size_t i = 0; i < wkts.size(); ++i) {
    Footprint f;
    f.polygons = gis::polygons_from_wkt(wkts[i]);
    f.source_id = "f" + std::to_string(i);
    out.push_back(std::move(f));
  }
  return out;
}

Mesh without_ground(const Mesh& m) {
  Mesh out;
  out.source_id = m.source_id;
  for (const MeshFace& f : m.faces) {
    if (f.kind == SurfaceKind::Ground) continue;
    std::vector<std::vector<Point3>> rings;
    for (std::uint32_t r = f.first_ring; r < f.first_ring + f.ring_count; ++r) {
      std::vector<Point3> ring;
      for (std::uint32_t k = m.ring_offsets[r]; k < m.ring_offsets[r + 1]; ++k) ring.push_back(m.vertices[m.indices[k]]);
      rings.push_back(std::move(ring));
    }
    out.add_face(rings, f.kind, f.lod);
  }
  return out;
}

}  // namespace groundplan::test

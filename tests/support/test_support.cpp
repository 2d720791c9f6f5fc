// SPDX-License-Identifier: MIT
#include "test_support.h"

#include "test_config.h"

#include <groundplan/gis/geos_reference.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

namespace groundplan::test {

TempDir::TempDir(const std::string& prefix) {
  static int n = 0;
  path = std::filesystem::temp_directory_path() /
         (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(n++));
  std::filesystem::create_directories(path);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path, ec);
}

std::string TempDir::file(const std::string& rel, const std::string& content) const {
  const std::filesystem::path p = path / rel;
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << content;
  return p.string();
}

std::vector<std::string> plan_keys(const std::vector<GroundPlan>& plans) {
  std::vector<std::string> out;
  for (const GroundPlan& p : plans) {
    std::string s;
    char buf[64];
    for (const Point2& q : p.polygon.outer) {
      std::snprintf(buf, sizeof buf, "%.6f %.6f,", q.x, q.y);
      s += buf;
    }
    out.push_back(s + "|" + std::to_string(p.polygon.holes.size()));
  }
  std::sort(out.begin(), out.end());
  return out;
}

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

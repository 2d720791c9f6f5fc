// SPDX-License-Identifier: MIT
#pragma once
// Meshes in a flat binary file, so that decompose_replay can time the decomposition on a machine
// without the GIS libraries (the GPU hosts): decompose_bench --dump writes the meshes it times,
// decompose_replay reads them. Little-endian as both machines are; a version word guards the layout.
// Also the one hash of decomposition results both programs print, so a replay elsewhere can show it
// computed the same footprints as here.
#include "footprint/decompose.h"

#include <groundplan/mesh.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace groundplan::bench {

struct MeshSet {
  std::string name;
  std::vector<Mesh> meshes;
};

inline constexpr char kDumpMagic[8] = {'G', 'P', 'M', 'E', 'S', 'H', '0', '1'};

namespace dump_detail {
struct File {
  std::FILE* f;
  ~File() {
    if (f) std::fclose(f);
  }
};
template <class T>
bool put_vec(std::FILE* f, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  return std::fwrite(&n, 8, 1, f) == 1 && (n == 0 || std::fwrite(v.data(), sizeof(T), n, f) == n);
}
template <class T>
bool get_vec(std::FILE* f, std::vector<T>& v, std::uint64_t max_items) {
  std::uint64_t n = 0;
  if (std::fread(&n, 8, 1, f) != 1 || n > max_items) return false;
  v.resize(n);
  return n == 0 || std::fread(v.data(), sizeof(T), n, f) == n;
}
}  // namespace dump_detail

inline bool write_mesh_sets(const std::string& path, const std::vector<MeshSet>& sets) {
  using namespace dump_detail;
  File F{std::fopen(path.c_str(), "wb")};
  if (!F.f) return false;
  std::FILE* f = F.f;
  bool ok = std::fwrite(kDumpMagic, 1, 8, f) == 8;
  const std::uint64_t ns = sets.size();
  ok = ok && std::fwrite(&ns, 8, 1, f) == 1;
  for (const MeshSet& s : sets) {
    ok = ok && put_vec(f, std::vector<char>(s.name.begin(), s.name.end()));
    const std::uint64_t nm = s.meshes.size();
    ok = ok && std::fwrite(&nm, 8, 1, f) == 1;
    for (const Mesh& m : s.meshes) {
      ok = ok && put_vec(f, m.vertices) && put_vec(f, m.indices) && put_vec(f, m.ring_offsets) && put_vec(f, m.faces);
      ok = ok && put_vec(f, std::vector<char>(m.source_id.begin(), m.source_id.end()));
    }
  }
  return ok;
}

/// False on a file that is not a dump of this layout or is cut short (sizes are bounded, so a
/// damaged file cannot ask for absurd allocations).
inline bool read_mesh_sets(const std::string& path, std::vector<MeshSet>& sets) {
  using namespace dump_detail;
  File F{std::fopen(path.c_str(), "rb")};
  if (!F.f) return false;
  std::FILE* f = F.f;
  char magic[8];
  std::uint64_t ns = 0;
  if (std::fread(magic, 1, 8, f) != 8 || std::memcmp(magic, kDumpMagic, 8) != 0) return false;
  if (std::fread(&ns, 8, 1, f) != 1 || ns > 1000) return false;
  constexpr std::uint64_t kMax = 1u << 28;
  sets.resize(ns);
  for (MeshSet& s : sets) {
    std::vector<char> name;
    std::uint64_t nm = 0;
    if (!get_vec(f, name, 4096) || std::fread(&nm, 8, 1, f) != 1 || nm > kMax) return false;
    s.name.assign(name.begin(), name.end());
    s.meshes.resize(nm);
    for (Mesh& m : s.meshes) {
      std::vector<char> id;
      if (!get_vec(f, m.vertices, kMax) || !get_vec(f, m.indices, kMax) || !get_vec(f, m.ring_offsets, kMax) ||
          !get_vec(f, m.faces, kMax) || !get_vec(f, id, 1 << 20))
        return false;
      m.source_id.assign(id.begin(), id.end());
      if (m.ring_offsets.empty()) return false;
    }
  }
  return true;
}

/// Hash of the bits of every footprint coordinate and of the shadow flag, over a set's meshes.
inline std::uint64_t decompose_hash(const std::vector<Mesh>& meshes) {
  std::uint64_t h = 0x9E3779B97F4A7C15ULL;
  auto add = [&](std::uint64_t v) {
    h ^= v + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
  };
  auto add_ring = [&](const Ring& r) {
    add(r.size());
    for (const Point2& p : r) {
      std::uint64_t bx, by;
      std::memcpy(&bx, &p.x, 8), std::memcpy(&by, &p.y, 8);
      add(bx), add(by);
    }
  };
  for (const Mesh& m : meshes) {
    const footprint::DecomposeResult r = footprint::decompose_footprint(m);
    add(r.polygons.size());
    add(r.stats.shadow);
    for (const Polygon& p : r.polygons) {
      add_ring(p.outer);
      add(p.holes.size());
      for (const Ring& q : p.holes) add_ring(q);
    }
  }
  return h;
}

}  // namespace groundplan::bench

// SPDX-License-Identifier: MIT
// Footprints per second by surface decomposition (issue 5 goal: >= 200k LoD2 buildings/s per core),
// on one core, against the explicit GroundSurface path on the same buildings. Meshes are read once
// into memory (GroundSurface faces removed for the decomposition, so it cannot take them); the
// figure is the median of repeated passes. Usage: decompose_bench [file ...] (default: every real
// CityGML sample with GroundSurfaces, grouped per file, plus the LoD1 tiles). `--passes N` runs exactly N
// decomposition passes per file instead and no timing (for instruction counts under
// `valgrind --tool=callgrind --toggle-collect='groundplan::footprint::decompose_footprint*'`).
// `--check [file ...]` (default: every input file under sample_data/ and the shared data) prints, per
// file, a hash of every decomposition's polygons (coordinate bits), stats and surface decomposition:
// a change that must not alter results is checked by comparing this output before and after.
// `--check-variants` hashes perturbed copies of every mesh too (weld tolerance, T-junctions, shadow).
// `--dump OUT [file ...]` writes the meshes it would time (same default files, GroundSurfaces removed)
// to OUT for decompose_replay, which times them on a machine without the GIS libraries.
#include "footprint/decompose.h"

#include <groundplan/footprint.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/reader.h>

#include <algorithm>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "decompose_dump.h"
#include "test_config.h"
#include "test_support.h"

namespace {

using namespace groundplan;
namespace fs = std::filesystem;

using test::without_ground;

using bench::median_seconds;

struct Set {
  std::string name;
  std::vector<Mesh> full, bare;  // with and without GroundSurface faces
  std::size_t faces = 0;
};

Set load(const std::string& path, bool ground_only) {
  Set s;
  s.name = fs::path(path).filename().string();
  std::vector<Problem> problems;
  gis::ReadInfo info;
  std::vector<Mesh> meshes;
  gis::read_any(path, {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
  std::unique_ptr<gis::WorkingFrame> frame;  // CityGML: as written; KML, COLLADA, glTF arrive placed
  if (!info.in_working_crs) try {
      frame = std::make_unique<gis::WorkingFrame>(info.citygml.srs_name, gis::CrsOptions{}, path);
    } catch (const std::exception&) {
    }
  for (Mesh& m : meshes) {
    const bool ground = std::any_of(m.faces.begin(), m.faces.end(), [](const MeshFace& f) { return f.kind == SurfaceKind::Ground; });
    if (ground_only && !ground) continue;
    if (frame && !frame->identity() && !frame->transform(m)) continue;
    s.bare.push_back(without_ground(m));
    s.faces += s.bare.back().faces.size();
    s.full.push_back(std::move(m));
  }
  return s;
}

int g_passes = 0;  // > 0: that many decomposition passes, no timing

void run(const Set& s) {
  if (s.bare.empty()) return;
  std::size_t sink = 0;
  if (g_passes > 0) {
    for (int p = 0; p < g_passes; ++p)
      for (const Mesh& m : s.bare) sink += footprint::decompose_footprint(m).polygons.size();
    std::printf("%-58s %6zu bldg x %d passes = %zu calls  [%zu]\n", s.name.c_str(), s.bare.size(), g_passes,
                s.bare.size() * g_passes, sink % 10);
    return;
  }
  const double dec = median_seconds([&] {
    for (const Mesh& m : s.bare) sink += footprint::decompose_footprint(m).polygons.size();
  });
  FootprintParams gp;
  gp.source = FootprintSource::GroundSurface;
  const double expl = median_seconds([&] {
    for (const Mesh& m : s.full) sink += make_footprint(m, gp).footprint.polygons.size();
  });
  const double n = static_cast<double>(s.bare.size());
  std::printf("%-58s %6zu bldg %6.1f faces/bldg  decompose %9.0f bldg/s (%6.2f us)  explicit %9.0f bldg/s  [%zu]\n",
              s.name.c_str(), s.bare.size(), s.faces / n, n / dec, 1e6 * dec / n, n / expl, sink % 10);
}

// ---- --check: result identity -------------------------------------------------------------------
struct Hasher {
  std::uint64_t h = 0x9E3779B97F4A7C15ULL;
  void add(std::uint64_t v) {
    h ^= v + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
  }
  void add(double d) {
    std::uint64_t b;
    std::memcpy(&b, &d, 8);
    add(b);
  }
  void add(const Ring& r) {
    add(std::uint64_t(r.size()));
    for (const Point2& p : r) add(p.x), add(p.y);
  }
};

void hash_result(Hasher& H, const footprint::DecomposeResult& r, const footprint::SurfaceDecomposition& d) {
  H.add(std::uint64_t(r.polygons.size()));
  for (const Polygon& p : r.polygons) {
    H.add(p.outer);
    H.add(std::uint64_t(p.holes.size()));
    for (const Ring& h : p.holes) H.add(h);
  }
  const footprint::DecomposeStats& s = r.stats;
  for (std::size_t v : {s.faces_used, s.duplicate_faces, s.vertices_welded, s.t_junction_splits, s.nonmanifold_edges,
                        s.components, s.unoriented_components, s.flipped_faces, s.footprint_edges, s.loops,
                        s.open_chains, s.holes, s.dropped_loops, s.chained_in_plan, std::size_t(s.shadow)})
    H.add(std::uint64_t(v));
  for (std::int32_t v : d.face_patch) H.add(std::uint64_t(std::uint32_t(v)));
  for (footprint::PatchKind k : d.patch_kind) H.add(std::uint64_t(k));
  for (double v : d.patch_z) H.add(v);
  for (double v : d.patch_area_m2) H.add(v);
}

bool g_variants = false;  // --check-variants: also perturbed copies of every mesh

/// Perturbed copies that reach the rarer paths: 0 = every vertex moved by up to 0.4 mm per axis
/// (shared corners are no longer bit-identical: welding within the tolerance), 1 = faces fanned
/// into triangles and every 5th triangle dropped (open edges, T-junction look, open chains,
/// shadow), 2 = every 4th vertex moved by up to 3 mm (near misses of the weld tolerance).
Mesh variant(const Mesh& m, int kind) {
  Mesh out = m;
  auto jitter = [](std::uint64_t i, int axis) {
    std::uint64_t h = (i * 3 + axis + 1) * 0x9E3779B97F4A7C15ULL;
    h ^= h >> 31;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 29;
    return (static_cast<double>(h >> 11) / 9007199254740992.0) * 2 - 1;  // [-1, 1)
  };
  if (kind == 0 || kind == 2) {
    for (std::size_t i = 0; i < out.vertices.size(); ++i) {
      if (kind == 2 && i % 4 != 0) continue;
      const double a = kind == 0 ? 4e-4 : 3e-3;
      out.vertices[i].x += a * jitter(i, 0);
      out.vertices[i].y += a * jitter(i, 1);
      out.vertices[i].z += a * jitter(i, 2);
    }
    return out;
  }
  out.indices.clear();
  out.ring_offsets.assign(1, 0);
  out.faces.clear();
  std::size_t tri = 0;
  for (const MeshFace& f : m.faces) {
    const std::uint32_t a = m.ring_offsets[f.first_ring], b = m.ring_offsets[f.first_ring + 1];
    for (std::uint32_t k = a + 1; k + 1 < b; ++k) {
      if (++tri % 5 == 0) continue;
      MeshFace t = f;
      t.first_ring = static_cast<std::uint32_t>(out.ring_count());
      t.ring_count = 1;
      for (std::uint32_t v : {m.indices[a], m.indices[k], m.indices[k + 1]}) out.indices.push_back(v);
      out.ring_offsets.push_back(static_cast<std::uint32_t>(out.indices.size()));
      out.faces.push_back(t);
    }
  }
  return out;
}

/// Hash of the decomposition of every mesh of `path` (GroundSurface faces removed where present),
/// with and without the decomposition output asked for, in the working frame as the tests use it.
int check_file(const std::string& path, Hasher& total) {
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  gis::ReadInfo info;
  try {
    gis::read_any(path, {}, [&](Mesh&& m) { meshes.push_back(std::move(m)); }, problems, info);
  } catch (const std::exception& e) {
    std::printf("%-70s unreadable (%s)\n", path.c_str(), e.what());
    return 0;
  }
  std::unique_ptr<gis::WorkingFrame> frame;
  if (!info.in_working_crs) try {
      frame = std::make_unique<gis::WorkingFrame>(info.citygml.srs_name, gis::CrsOptions{}, path);
    } catch (const std::exception&) {
    }
  Hasher H;
  std::size_t n = 0, shadow = 0, polys = 0, faces = 0;
  for (Mesh& m : meshes) {
    if (frame && !frame->identity() && !frame->transform(m)) continue;
    const bool ground = std::any_of(m.faces.begin(), m.faces.end(), [](const MeshFace& f) { return f.kind == SurfaceKind::Ground; });
    const Mesh bare = ground ? without_ground(m) : Mesh{};
    const Mesh& in = ground ? bare : m;
    footprint::SurfaceDecomposition d;
    const footprint::DecomposeResult r = footprint::decompose_footprint(in, {}, &d);
    const footprint::DecomposeResult r2 = footprint::decompose_footprint(in);
    hash_result(H, r, d);
    hash_result(H, r2, footprint::SurfaceDecomposition{});
    if (g_variants)
      for (int v = 0; v < 3; ++v) hash_result(H, footprint::decompose_footprint(variant(in, v)), footprint::SurfaceDecomposition{});
    ++n;
    shadow += r.stats.shadow;
    polys += r.polygons.size();
    faces += in.faces.size();
  }
  std::printf("%-70s %6zu meshes %8zu faces %6zu polygons %4zu shadow  %016llx\n",
              fs::relative(path, fs::path(GROUNDPLAN_SHARED_DATA_DIR).parent_path().parent_path()).string().c_str(), n,
              faces, polys, shadow, static_cast<unsigned long long>(H.h));
  total.add(H.h);
  return 1;
}

int check(int argc, char** argv, int first) {
  std::vector<std::string> files;
  for (int i = first; i < argc; ++i) files.push_back(argv[i]);
  if (files.empty())
    for (const char* dir : {GROUNDPLAN_SAMPLE_DATA_DIR, GROUNDPLAN_SHARED_DATA_DIR}) {
      if (!fs::is_directory(dir)) continue;
      for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file() && gis::is_input_name(e.path().filename().string())) files.push_back(e.path().string());
    }
  std::sort(files.begin(), files.end());
  Hasher total;
  for (const std::string& f : files) check_file(f, total);
  std::printf("total %016llx\n", static_cast<unsigned long long>(total.h));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::pair<std::string, bool>> files;
  int first = 1;
  std::string dump;
  if (argc > 1 && std::string(argv[1]) == "--check") return check(argc, argv, 2);
  if (argc > 1 && std::string(argv[1]) == "--check-variants") return g_variants = true, check(argc, argv, 2);
  if (argc > 2 && std::string(argv[1]) == "--passes") {
    g_passes = std::max(1, std::atoi(argv[2]));
    first = 3;
  }
  if (argc > 2 && std::string(argv[1]) == "--dump") {
    dump = argv[2];
    first = 3;
  }
  if (argc > first) {
    for (int i = first; i < argc; ++i) files.emplace_back(argv[i], false);
  } else {
    const std::string d = GROUNDPLAN_SHARED_DATA_DIR;
    for (const char* f : {"/citygml1-berlin-lod2-libcitygml/berlin_open_data_sample_data.citygml",
                          "/citygml-citygml4j-samples/lod2_buildings_v3.gml",
                          "/citygml-fzkhaus-denhaag-misc/DenHaag_1BwBP.gml",
                          "/citygml-fzkhaus-denhaag-misc/FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml",
                          "/citygml-ogc-spec-samples/Opera-Lyon_CityGML3.0_LOD2_with_xAL3_FreeText.gml",
                          "/citygml-ogc-spec-samples/plateau_53394517_bldg_6697_2_op_CityGML2.gml",
                          "/citygml-fzkhaus-denhaag-misc/TUM-Main-Entrance.gml"})
      files.emplace_back(d + f, true);
    // LoD1 solids without GroundSurface: the decomposition on whole tiles.
    files.emplace_back(d + "/citygml1-niedersachsen-lod1-4tiles/LoD1_24065860_2_2021-01-25.gml", false);
    files.emplace_back(d + "/citygml2-plateau-japan-lod1/53395404_bldg_6697_op.gml", false);
    // COLLADA placed by KML (SketchUp export, no ground): the decomposition is the only way there.
    files.emplace_back(d + "/kml-collada-macky-google/macky-normal.kmz", false);
    for (const char* k : {"a_bd001.kml", "a_bd002.kml", "a_bd003.kml"})
      files.emplace_back(d + "/kml-collada-korea-mago/sample-kml/" + k, false);
  }
  std::vector<bench::MeshSet> sets;
  for (const auto& [path, ground_only] : files) {
    try {
      Set s = load(path, ground_only);
      if (dump.empty()) run(s);
      else if (!s.bare.empty()) sets.push_back(bench::MeshSet{s.name, std::move(s.bare)});
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), e.what());
    }
  }
  if (!dump.empty()) {
    if (!bench::write_mesh_sets(dump, sets)) {
      std::fprintf(stderr, "%s: cannot write\n", dump.c_str());
      return 1;
    }
    for (const bench::MeshSet& s : sets)
      std::printf("%-58s %6zu meshes  result hash %016llx\n", s.name.c_str(), s.meshes.size(),
                  static_cast<unsigned long long>(bench::decompose_hash(s.meshes)));
  }
  return 0;
}

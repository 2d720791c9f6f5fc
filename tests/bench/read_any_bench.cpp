// SPDX-License-Identifier: MIT
// MB/s from a file on disk to meshes through gis::read_any (issue 6), the median of N runs, one core.
// tests/bench/read_vs_ogrinfo.sh runs it beside `ogrinfo -al -q` (GDAL's own GML driver) on the same
// file. Usage: read_any_bench FILE [runs=5] [--origin lon,lat,alt] [--digest]
// --digest also prints an FNV-1a hash of every mesh (ids, coordinates bit for bit, rings, faces) and
// every problem, in reading order: two builds read a file identically when their digests agree.
#include <groundplan/gis/reader.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

/// FNV-1a over bytes; strings are hashed with their length so that "ab","c" and "a","bc" differ.
struct Digest {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  void str(const std::string& s) {
    const std::uint64_t n = s.size();
    bytes(&n, sizeof n);
    bytes(s.data(), s.size());
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    const std::uint64_t n = v.size();
    bytes(&n, sizeof n);
    if (n) bytes(v.data(), v.size() * sizeof(T));
  }
  void mesh(const groundplan::Mesh& m) {
    vec(m.vertices);
    vec(m.indices);
    vec(m.ring_offsets);
    for (const groundplan::MeshFace& f : m.faces) {  // field by field: no padding bytes
      bytes(&f.first_ring, sizeof f.first_ring);
      bytes(&f.ring_count, sizeof f.ring_count);
      bytes(&f.kind, sizeof f.kind);
      bytes(&f.lod, sizeof f.lod);
    }
    str(m.source_id);
    str(m.parent_id);
    str(m.source_file);
    str(m.name);
    bytes(&m.measured_height, sizeof m.measured_height);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE [runs] [--origin lon,lat,alt]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  int runs = 5;
  bool digest = false;
  Digest mesh_digest, problem_digest;
  groundplan::gis::ReadOptions options;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--origin" && i + 1 < argc) options.origin = argv[++i];
    else if (a == "--digest") digest = true;
    else runs = std::max(1, std::atoi(argv[i]));
  }
  const double mb = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  std::vector<double> seconds;
  std::size_t meshes = 0, faces = 0;
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  try {
    for (int r = 0; r < runs; ++r) {
      std::vector<groundplan::Problem> problems;
      groundplan::gis::ReadInfo info;
      meshes = faces = 0;
      mesh_digest = problem_digest = Digest{};
      const auto t0 = std::chrono::steady_clock::now();
      groundplan::gis::read_any(path, options, [&](groundplan::Mesh&& m) {
        ++meshes;
        faces += m.faces.size();
        if (digest) mesh_digest.mesh(m);
        for (const groundplan::Point3& p : m.vertices) {
          const double v[3] = {p.x, p.y, p.z};
          for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
        }
      }, problems, info);
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      if (digest)
        for (const groundplan::Problem& p : problems)
          for (const std::string* s : {&p.source_id, &p.file, &p.stage, &p.code, &p.reason}) problem_digest.str(*s);
      if (digest && r == 0) std::printf("problems %zu\n", problems.size());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  std::sort(seconds.begin(), seconds.end());
  const double median = seconds[seconds.size() / 2];
  if (meshes)
    std::printf("extent %.3f %.3f %.3f .. %.3f %.3f %.3f (size %.3f x %.3f x %.3f)\n", lo[0], lo[1], lo[2], hi[0], hi[1],
              hi[2], hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  std::printf("file %s\nsize_mb %.3f\nmeshes %zu\nfaces %zu\nruns %d\nmedian_s %.4f\nmin_s %.4f\nmb_per_s %.1f\n",
              path.c_str(), mb, meshes, faces, runs, median, seconds.front(), mb / median);
  if (digest)
    std::printf("mesh_digest %016llx\nproblem_digest %016llx\n", static_cast<unsigned long long>(mesh_digest.h),
                static_cast<unsigned long long>(problem_digest.h));
  return 0;
}

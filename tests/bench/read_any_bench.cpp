// SPDX-License-Identifier: MIT
// MB/s from a file on disk to meshes through gis::read_any (issue 6), the median of N runs, one core.
// tests/bench/read_vs_ogrinfo.sh runs it beside `ogrinfo -al -q` (GDAL's own GML driver) on the same
// file. Usage: read_any_bench FILE [runs=5] [--origin lon,lat,alt]
#include <groundplan/gis/reader.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE [runs] [--origin lon,lat,alt]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  int runs = 5;
  groundplan::gis::ReadOptions options;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--origin" && i + 1 < argc) options.origin = argv[++i];
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
      const auto t0 = std::chrono::steady_clock::now();
      groundplan::gis::read_any(path, options, [&](groundplan::Mesh&& m) {
        ++meshes;
        faces += m.faces.size();
        for (const groundplan::Point3& p : m.vertices) {
          const double v[3] = {p.x, p.y, p.z};
          for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
        }
      }, problems, info);
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
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
  return 0;
}

// SPDX-License-Identifier: MIT
// KML/KMZ + COLLADA, glTF/GLB, CityJSON/CityJSONSeq (issue 16) and 3D Tiles (b3dm, cmpt, tileset.json) readers on arbitrary bytes (issue 8), through read_any on a /vsimem/
// file: byte 0 picks the format (the extension), the rest is the file. A .kml may link "m.dae", which
// is the same bytes again (so COLLADA is reached through KML too). Expected outcomes: meshes,
// Problems, or an InputError; anything else is a finding.
#include "fuzz_entry.h"

#include <groundplan/error.h>
#include <groundplan/gis/reader.h>

#include <cpl_vsi.h>

#include <cmath>
#include <string>

namespace {

void put(const std::string& path, const std::uint8_t* data, std::size_t size) {
  VSILFILE* f = VSIFileFromMemBuffer(path.c_str(), const_cast<GByte*>(data), size, FALSE);
  if (f) VSIFCloseL(f);
}

}  // namespace

GROUNDPLAN_FUZZ_TARGET(read_any) {
  using namespace groundplan;
  if (size < 1) return 0;
  // A tileset.json's contents name files beside it: "m.dae" is there (the same bytes), the rest is missing.
  static const char* kExt[] = {".kml", ".kmz", ".dae", ".gltf", ".glb", ".city.json", ".city.jsonl", ".b3dm", ".cmpt",
                               "/tileset.json"};
  const std::string dir = "/vsimem/fuzz_read_any";
  const std::string ext = kExt[data[0] % 10];
  const std::string path = dir + (ext[0] == '/' ? ext : "/input" + ext);
  put(path, data + 1, size - 1);
  put(dir + "/m.dae", data + 1, size - 1);
  gis::ReadOptions options;
  options.origin = "127.17,37.62,0";
  options.kml.max_entry_bytes = 1 << 20;  // keep zip inflation small (the bound itself is under test)
  options.kml.max_total_bytes = 4 << 20;
  options.kml.collada.max_vertices = 1 << 16;
  options.gltf.max_bytes = 1 << 20;
  options.gltf.max_vertices = 1 << 16;
  options.cityjson.max_line_bytes = 1 << 20;
  std::vector<Problem> problems;
  gis::ReadInfo info;
  auto check = [](Mesh&& m) {
    for (const Point3& p : m.vertices)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        groundplan_fuzz_fail("read_any", "a delivered mesh has a non-finite vertex");
    for (std::uint32_t i : m.indices)
      if (i >= m.vertices.size()) groundplan_fuzz_fail("read_any", "a mesh index is out of range");
  };
  try {
    gis::read_any(path, options, check, problems, info);
  } catch (const InputError&) {
  } catch (const InvalidArgument&) {
  }
  VSIUnlink(path.c_str());
  VSIUnlink((dir + "/m.dae").c_str());
  return 0;
}

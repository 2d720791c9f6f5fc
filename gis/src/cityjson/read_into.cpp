// SPDX-License-Identifier: MIT
#include "cityjson/read_into.h"

namespace groundplan::gis::cityjson {

void read_into(const std::string& path, const ReadOptions& options, std::uint64_t max_bytes, const MeshCallback& on_mesh,
               std::vector<Problem>& problems, ReadInfo& info) {
  CityJsonOptions opt = options.cityjson;
  opt.lod = options.lod;
  opt.lod_refinement = options.lod_refinement;
  if (max_bytes) opt.max_bytes = max_bytes;
  opt.on_bytes = options.on_bytes;
  // The CRS as the pipeline reads it for CityGML: set before the first mesh (the pipeline makes the
  // working frame then; CityJSON's metadata is read before any object), and again at the end.
  struct Publish {
    ReadInfo& info;
    ~Publish() { (*this)(); }
    void operator()() const {
      SourceInfo& s = info.citygml;
      s.file = info.file;
      s.srs_name = info.cityjson.reference_system;
      s.has_envelope = info.cityjson.has_extent;
      for (int i = 0; i < 3; ++i) {
        s.envelope_lower[i] = info.cityjson.extent[i];
        s.envelope_upper[i] = info.cityjson.extent[i + 3];
      }
      s.buildings = info.cityjson.buildings;
      s.building_parts = info.cityjson.building_parts;
      s.meshes = info.cityjson.meshes;
      s.buildings_dropped = info.cityjson.buildings_dropped;
      s.bytes = info.cityjson.bytes;
    }
  } publish{info};
  auto count = [&](Mesh&& m) {
    if (info.meshes++ == 0) publish();
    on_mesh(std::move(m));
  };
  if (info.format == InputFormat::CityJsonSeq)
    read_cityjson_seq(path, opt, count, problems, info.cityjson);
  else
    read_cityjson(path, opt, count, problems, info.cityjson);
}

}  // namespace groundplan::gis::cityjson

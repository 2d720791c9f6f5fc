// SPDX-License-Identifier: MIT
// b3dm, cmpt and glTF contents of 3D Tiles (tile_content.h), after the 3D Tiles 1.0 specification's
// Batched 3D Model and Composite formats: little-endian headers, JSON + binary feature and batch tables.
#include "tiles3d/tile_content.h"

#include <groundplan/error.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

namespace groundplan::gis::tiles3d {
namespace {

constexpr int kMaxCompositeDepth = 8;

std::uint32_t u32(const std::string& b, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

/// The names of the features of a JSON batch table: its id property (options' id_field, else gml_id,
/// id, name), one entry per feature; empty when it has none.
std::shared_ptr<std::vector<std::string>> batch_names(const nlohmann::json& table, const std::string& id_field) {
  if (!table.is_object()) return nullptr;
  const std::vector<std::string> fields = id_field.empty() ? std::vector<std::string>{"gml_id", "id", "name"}
                                                           : std::vector<std::string>{id_field};
  for (const std::string& f : fields) {
    auto it = table.find(f);
    if (it == table.end() || !it->is_array()) continue;  // a binary property ({"byteOffset": ...}) names nothing
    auto names = std::make_shared<std::vector<std::string>>();
    for (const auto& v : *it) {
      if (v.is_string()) names->push_back(v.get<std::string>());
      else if (v.is_number_integer()) names->push_back(std::to_string(v.get<std::int64_t>()));
      else names->push_back({});
    }
    return names;
  }
  return nullptr;
}

nlohmann::json parse_json_section(const std::string& bytes, std::size_t at, std::size_t length, const std::string& path,
                                  const char* what) {
  if (length == 0) return nlohmann::json::object();
  std::string_view text(bytes.data() + at, length);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\0')) text.remove_suffix(1);  // padding
  try {
    return nlohmann::json::parse(text.begin(), text.end());
  } catch (const std::exception& e) {
    throw InputError(path + ": the " + std::string(what) + " JSON cannot be parsed: " + e.what());
  }
}

void read_b3dm(const std::string& path, const std::string& label, const std::string& b, const std::string& root_folder,
               const Mat4& transform, const Tiles3dOptions& options, const GltfMeshCallback& on_mesh,
               std::vector<Problem>& problems, Tiles3dInfo& info) {
  if (b.size() < 28)
    throw InputError(path + ": truncated b3dm: " + std::to_string(b.size()) + " bytes, its header alone takes 28");
  const std::uint32_t version = u32(b, 4), length = u32(b, 8);
  if (version != 1) throw InputError(path + ": b3dm version " + std::to_string(version) + " is not read (only 1)");
  if (length > b.size())
    throw InputError(path + ": its b3dm header says " + std::to_string(length) + " bytes, the tile has " +
                     std::to_string(b.size()) + " (truncated, or a lying byteLength)");
  std::uint64_t header = 28, ftj = u32(b, 12), ftb = u32(b, 16), btj = u32(b, 20), btb = u32(b, 24);
  // Two legacy headers (before 3D Tiles 1.0) are told apart by a length that would be absurd.
  if (btj >= 570425344u) header = 20, btj = u32(b, 16), ftj = ftb = btb = 0;
  else if (btb >= 570425344u) header = 24, btj = u32(b, 12), btb = u32(b, 16), ftj = ftb = 0;
  if (header + ftj + ftb + btj + btb > length)
    throw InputError(path + ": its b3dm feature and batch tables (" + std::to_string(ftj + ftb + btj + btb) +
                     " bytes) reach past its byteLength " + std::to_string(length));
  const nlohmann::json ft = parse_json_section(b, header, ftj, path, "b3dm feature table");
  const std::size_t ft_binary = header + ftj;
  const nlohmann::json bt = parse_json_section(b, ft_binary + ftb, btj, path, "b3dm batch table");
  GltfTile tile;
  tile.transform = transform;
  tile.feature_prefix = label;
  if (ft.is_object() && ft.contains("RTC_CENTER")) {
    const nlohmann::json& c = ft["RTC_CENTER"];
    double v[3] = {NAN, NAN, NAN};
    if (c.is_array() && c.size() == 3 && c[0].is_number() && c[1].is_number() && c[2].is_number()) {
      for (int k = 0; k < 3; ++k) v[k] = c[k].get<double>();
    } else if (c.is_object() && c.contains("byteOffset") && c["byteOffset"].is_number_unsigned()) {
      const std::uint64_t off = c["byteOffset"].get<std::uint64_t>();
      if (off <= ftb && ftb - off >= 12)
        for (int k = 0; k < 3; ++k) {
          float f;
          std::memcpy(&f, b.data() + ft_binary + off + 4 * static_cast<std::size_t>(k), 4);
          v[k] = f;
        }
    }
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw InputError(path + ": the b3dm feature table's RTC_CENTER is not three finite numbers");
    tile.has_rtc_center = true;
    tile.rtc_center = {v[0], v[1], v[2]};
  }
  if (auto names = batch_names(bt, options.gltf.id_field))
    tile.feature_name = [names](std::int64_t id) {
      return id >= 0 && static_cast<std::size_t>(id) < names->size() ? (*names)[static_cast<std::size_t>(id)] : std::string();
    };
  const std::size_t glb_at = static_cast<std::size_t>(header + ftj + ftb + btj + btb);
  GltfInfo gi;
  read_gltf_bytes(path, b.substr(glb_at, length - glb_at), root_folder, options.gltf, &tile, on_mesh, problems, gi);
  ++info.contents;
  if (!gi.georeference.empty()) info.georeference = gi.georeference;
  info.by_feature = info.by_feature || gi.by_feature;
}

}  // namespace

void read_content(const std::string& path, const std::string& label, const std::string& b,
                  const std::string& root_folder, const Mat4& transform, const Tiles3dOptions& options,
                  const GltfMeshCallback& on_mesh, std::vector<Problem>& problems, Tiles3dInfo& info, int depth) {
  const std::string magic = b.substr(0, 4);
  if (magic == "b3dm") return read_b3dm(path, label, b, root_folder, transform, options, on_mesh, problems, info);
  if (magic == "cmpt") {
    if (b.size() < 16)
      throw InputError(path + ": truncated cmpt: " + std::to_string(b.size()) + " bytes, its header alone takes 16");
    if (depth >= kMaxCompositeDepth)
      throw InputError(path + ": composite tiles nested deeper than " + std::to_string(kMaxCompositeDepth) + " levels");
    const std::uint32_t length = u32(b, 8), count = u32(b, 12);
    if (length > b.size())
      throw InputError(path + ": its cmpt header says " + std::to_string(length) + " bytes, the tile has " +
                       std::to_string(b.size()) + " (truncated, or a lying byteLength)");
    std::size_t at = 16;
    for (std::uint32_t k = 0; k < count; ++k) {
      if (length - at < 12)
        throw InputError(path + ": cmpt inner tile " + std::to_string(k) + " of " + std::to_string(count) +
                         " lies past its byteLength");
      const std::uint32_t inner = u32(b, at + 8);
      if (inner < 12 || inner > length - at)
        throw InputError(path + ": cmpt inner tile " + std::to_string(k) + " says " + std::to_string(inner) +
                         " bytes, " + std::to_string(length - at) + " are left");
      read_content(path, label + "/" + std::to_string(k), b.substr(at, inner), root_folder, transform, options, on_mesh,
                   problems, info, depth + 1);
      at += inner;
    }
    return;
  }
  if (magic == "i3dm" || magic == "pnts" || magic == "vctr" || magic == "geom")
    throw InputError(path + ": " + magic + " tiles (" +
                     (magic == "i3dm" ? "instanced models" : magic == "pnts" ? "point clouds" : "vector data") +
                     ") are not read");
  const auto first = b.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (magic == "glTF" || (first != std::string::npos && b[first] == '{')) {
    GltfTile tile;
    tile.transform = transform;
    tile.feature_prefix = label;
    GltfInfo gi;
    read_gltf_bytes(path, b, root_folder, options.gltf, &tile, on_mesh, problems, gi);
    ++info.contents;
    if (!gi.georeference.empty()) info.georeference = gi.georeference;
    info.by_feature = info.by_feature || gi.by_feature;
    return;
  }
  throw InputError(path + ": not a 3D Tiles content this reader knows (b3dm, cmpt, glb, glTF)");
}

}  // namespace groundplan::gis::tiles3d

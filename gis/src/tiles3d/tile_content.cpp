// SPDX-License-Identifier: MIT
// b3dm, cmpt and glTF contents of 3D Tiles (tile_content.h), after the 3D Tiles 1.0 specification's
// Batched 3D Model and Composite formats: little-endian headers, JSON + binary feature and batch tables.
#include "tiles3d/tile_content.h"

#include "collada/collada_internal.h"

#include <groundplan/error.h>

#include <GeographicLib/Geocentric.hpp>
#include <nlohmann/json.hpp>

#include <array>
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

/// The byteLength of a b3dm or i3dm tile (`kind`) once its header's size, version and byteLength are checked
/// against the bytes there are.
std::uint32_t checked_length(const std::string& path, const std::string& b, const std::string& kind, std::size_t header) {
  if (b.size() < header)
    throw InputError(path + ": truncated " + kind + ": " + std::to_string(b.size()) + " bytes, its header alone takes " +
                     std::to_string(header));
  const std::uint32_t version = u32(b, 4), length = u32(b, 8);
  if (version != 1) throw InputError(path + ": " + kind + " version " + std::to_string(version) + " is not read (only 1)");
  if (length > b.size())
    throw InputError(path + ": its " + kind + " header says " + std::to_string(length) + " bytes, the tile has " +
                     std::to_string(b.size()) + " (truncated, or a lying byteLength)");
  return length;
}

void read_b3dm(const std::string& path, const std::string& label, const std::string& b, const std::string& root_folder,
               const Mat4& transform, const Tiles3dOptions& options, const GltfMeshCallback& on_mesh,
               std::vector<Problem>& problems, Tiles3dInfo& info) {
  const std::uint32_t length = checked_length(path, b, "b3dm", 28);
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

/// A feature table property of `count` elements of `width` bytes: in the binary body at its byteOffset.
/// nullptr when absent; throws when it is there but does not fit.
const unsigned char* ft_binary(const nlohmann::json& ft, const char* name, const std::string& b, std::size_t body,
                               std::size_t body_length, std::size_t count, std::size_t width, const std::string& path) {
  if (!ft.contains(name)) return nullptr;
  const nlohmann::json& p = ft[name];
  if (!p.is_object() || !p.contains("byteOffset") || !p["byteOffset"].is_number_unsigned())
    throw InputError(path + ": the i3dm feature table's " + name + " has no byteOffset");
  const std::uint64_t off = p["byteOffset"].get<std::uint64_t>();
  if (off > body_length || (body_length - off) / width < count)
    throw InputError(path + ": the i3dm feature table's " + name + " reaches past its binary body");
  return reinterpret_cast<const unsigned char*>(b.data()) + body + off;
}

bool vec3_json(const nlohmann::json& ft, const char* name, double v[3]) {
  if (!ft.contains(name)) return false;
  const nlohmann::json& c = ft[name];
  if (!c.is_array() || c.size() != 3 || !c[0].is_number() || !c[1].is_number() || !c[2].is_number()) return false;
  for (int k = 0; k < 3; ++k) v[k] = c[static_cast<std::size_t>(k)].get<double>();
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

std::array<double, 3> f32x3(const unsigned char* p, std::size_t i) {
  float f[3];
  std::memcpy(f, p + 12 * i, 12);
  return {f[0], f[1], f[2]};
}

/// An oct-encoded unit vector (two uint16 in [0, 65535]).
std::array<double, 3> oct32p(const unsigned char* p, std::size_t i) {
  std::uint16_t q[2];
  std::memcpy(q, p + 4 * i, 4);
  double x = q[0] / 65535.0 * 2 - 1, y = q[1] / 65535.0 * 2 - 1, z = 1 - std::abs(x) - std::abs(y);
  if (z < 0) {
    const double ox = x;
    x = (1 - std::abs(y)) * (x >= 0 ? 1 : -1);
    y = (1 - std::abs(ox)) * (y >= 0 ? 1 : -1);
  }
  const double n = std::sqrt(x * x + y * y + z * z);
  return {x / n, y / n, z / n};
}

void read_i3dm(const std::string& path, const std::string& label, const std::string& b, const std::string& root_folder,
               const Mat4& transform, const Tiles3dOptions& options, const GltfMeshCallback& on_mesh,
               std::vector<Problem>& problems, Tiles3dInfo& info) {
  const std::uint32_t length = checked_length(path, b, "i3dm", 32);
  const std::uint64_t ftj = u32(b, 12), ftb = u32(b, 16), btj = u32(b, 20), btb = u32(b, 24);
  if (32 + ftj + ftb + btj + btb > length)
    throw InputError(path + ": its i3dm feature and batch tables (" + std::to_string(ftj + ftb + btj + btb) +
                     " bytes) reach past its byteLength " + std::to_string(length));
  if (u32(b, 28) != 1)
    throw InputError(path + ": its glTF is given by uri (gltfFormat 0), which is not read: only an embedded glb");
  const nlohmann::json ft = parse_json_section(b, 32, ftj, path, "i3dm feature table");
  const nlohmann::json bt = parse_json_section(b, 32 + ftj + ftb, btj, path, "i3dm batch table");
  if (!ft.is_object() || !ft.contains("INSTANCES_LENGTH") || !ft["INSTANCES_LENGTH"].is_number_unsigned())
    throw InputError(path + ": the i3dm feature table has no INSTANCES_LENGTH");
  const std::uint64_t n64 = ft["INSTANCES_LENGTH"].get<std::uint64_t>();
  if (n64 > ftb) throw InputError(path + ": INSTANCES_LENGTH " + std::to_string(n64) + " is more than its feature table holds");
  const std::size_t n = static_cast<std::size_t>(n64), body = static_cast<std::size_t>(32 + ftj),
                    body_length = static_cast<std::size_t>(ftb);
  const unsigned char* pos = ft_binary(ft, "POSITION", b, body, body_length, n, 12, path);
  const unsigned char* qpos = pos ? nullptr : ft_binary(ft, "POSITION_QUANTIZED", b, body, body_length, n, 6, path);
  double qoff[3] = {0, 0, 0}, qscale[3] = {0, 0, 0};
  if (!pos && !qpos) throw InputError(path + ": the i3dm has neither POSITION nor POSITION_QUANTIZED");
  if (qpos && (!vec3_json(ft, "QUANTIZED_VOLUME_OFFSET", qoff) || !vec3_json(ft, "QUANTIZED_VOLUME_SCALE", qscale)))
    throw InputError(path + ": POSITION_QUANTIZED without QUANTIZED_VOLUME_OFFSET and _SCALE");
  const unsigned char* up = ft_binary(ft, "NORMAL_UP", b, body, body_length, n, 12, path);
  const unsigned char* right = ft_binary(ft, "NORMAL_RIGHT", b, body, body_length, n, 12, path);
  const unsigned char* up_oct = ft_binary(ft, "NORMAL_UP_OCT32P", b, body, body_length, n, 4, path);
  const unsigned char* right_oct = ft_binary(ft, "NORMAL_RIGHT_OCT32P", b, body, body_length, n, 4, path);
  const unsigned char* scale = ft_binary(ft, "SCALE", b, body, body_length, n, 4, path);
  const unsigned char* scale3 = ft_binary(ft, "SCALE_NON_UNIFORM", b, body, body_length, n, 12, path);
  std::size_t id_width = 2;
  if (ft.contains("BATCH_ID") && ft["BATCH_ID"].is_object() && ft["BATCH_ID"].contains("componentType")) {
    const std::string t = ft["BATCH_ID"]["componentType"].is_string() ? ft["BATCH_ID"]["componentType"].get<std::string>() : "";
    id_width = t == "UNSIGNED_BYTE" ? 1 : t == "UNSIGNED_INT" ? 4 : 2;
  }
  const unsigned char* batch = ft_binary(ft, "BATCH_ID", b, body, body_length, n, id_width, path);
  double rtc[3] = {0, 0, 0};
  if (ft.contains("RTC_CENTER") && !vec3_json(ft, "RTC_CENTER", rtc))
    throw InputError(path + ": the i3dm feature table's RTC_CENTER is not three finite numbers");
  const bool enu = ft.contains("EAST_NORTH_UP") && ft["EAST_NORTH_UP"].is_boolean() && ft["EAST_NORTH_UP"].get<bool>();
  const auto names = batch_names(bt, options.gltf.id_field);

  std::vector<GltfTile> instances(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::array<double, 3> p{};
    if (pos) {
      p = f32x3(pos, i);
    } else {
      std::uint16_t q[3];
      std::memcpy(q, qpos + 6 * i, 6);
      for (int k = 0; k < 3; ++k) p[static_cast<std::size_t>(k)] = qoff[k] + q[k] / 65535.0 * qscale[k];
    }
    for (int k = 0; k < 3; ++k) p[static_cast<std::size_t>(k)] += rtc[k];
    // The instance's axes: right (x), up (y), right x up (z); default the tile's axes, or east-north-up.
    std::array<double, 3> r{1, 0, 0}, u{0, 1, 0};
    if (up && right) {
      u = f32x3(up, i), r = f32x3(right, i);
    } else if (up_oct && right_oct) {
      u = oct32p(up_oct, i), r = oct32p(right_oct, i);
    } else if (enu) {
      double lat = 0, lon = 0, h = 0;
      GeographicLib::Geocentric::WGS84().Reverse(p[0], p[1], p[2], lat, lon, h);
      const double la = lat * M_PI / 180, lo = lon * M_PI / 180;
      r = {-std::sin(lo), std::cos(lo), 0};                                                // east
      u = {-std::sin(la) * std::cos(lo), -std::sin(la) * std::sin(lo), std::cos(la)};  // north
    }
    const std::array<double, 3> f{r[1] * u[2] - r[2] * u[1], r[2] * u[0] - r[0] * u[2], r[0] * u[1] - r[1] * u[0]};
    std::array<double, 3> sc{1, 1, 1};
    if (scale) {
      float v;
      std::memcpy(&v, scale + 4 * i, 4);
      sc = {v, v, v};
    }
    if (scale3) sc = f32x3(scale3, i);
    Mat4 m = {r[0] * sc[0], u[0] * sc[1], f[0] * sc[2], p[0], r[1] * sc[0], u[1] * sc[1], f[1] * sc[2], p[1],
              r[2] * sc[0], u[2] * sc[1], f[2] * sc[2], p[2], 0, 0, 0, 1};
    for (double v : m)
      if (!std::isfinite(v)) throw InputError(path + ": instance " + std::to_string(i) + "'s placement is not finite");
    std::int64_t id = static_cast<std::int64_t>(i);
    if (batch) {
      std::uint32_t v = 0;
      std::memcpy(&v, batch + id_width * i, id_width);  // little-endian
      id = v;
    }
    std::string name = names && static_cast<std::size_t>(id) < names->size() ? (*names)[static_cast<std::size_t>(id)] : "";
    instances[i].transform = detail::multiply(transform, m);
    instances[i].building = name.empty() ? label + "#" + std::to_string(id) : name;
  }
  const std::size_t glb_at = static_cast<std::size_t>(32 + ftj + ftb + btj + btb);
  GltfInfo gi;
  read_gltf_instances(path, b.substr(glb_at, length - glb_at), root_folder, options.gltf, instances, on_mesh, problems, gi);
  ++info.contents;
  if (!gi.georeference.empty()) info.georeference = gi.georeference;
  info.by_feature = true;
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
  if (magic == "i3dm") return read_i3dm(path, label, b, root_folder, transform, options, on_mesh, problems, info);
  if (magic == "pnts" || magic == "vctr" || magic == "geom")
    throw InputError(path + ": " + magic + " tiles (" + (magic == "pnts" ? "point clouds" : "vector data") +
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

// SPDX-License-Identifier: MIT
// Compressed glTF (gltf_extensions.h): Draco through Debian's libdraco, meshopt through Debian's
// libmeshoptimizer. tinygltf's own Draco code is not used: it indexes buffer views and accessors
// without checking them.
#include "gltf/gltf_extensions.h"

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <draco/compression/decode.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace groundplan::gis::gltf {
namespace {

constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kMeshoptExt = "EXT_meshopt_compression";
constexpr const char* kMeshoptKhr = "KHR_meshopt_compression";
constexpr std::uint64_t kMaxDecoded = std::uint64_t{1} << 31;  // bytes one view or primitive may decode to

bool starts_with(const std::string& s, std::string_view p) { return s.compare(0, p.size(), p) == 0; }

const tinygltf::Value* meshopt_of(const tinygltf::ExtensionMap& ext) {
  auto it = ext.find(kMeshoptKhr);
  if (it == ext.end()) it = ext.find(kMeshoptExt);
  return it == ext.end() ? nullptr : &it->second;
}

/// An unsigned integer member of a tinygltf object; false when absent, negative or not a number.
bool get_uint(const tinygltf::Value& v, const char* key, std::uint64_t& out) {
  if (!v.Has(key) || !v.Get(key).IsNumber()) return false;
  const double d = v.Get(key).GetNumberAsDouble();
  if (!(d >= 0) || d > 9.0e15 || d != static_cast<double>(static_cast<std::uint64_t>(d))) return false;
  out = static_cast<std::uint64_t>(d);
  return true;
}

std::string get_string(const tinygltf::Value& v, const char* key, const std::string& fallback) {
  return v.Has(key) && v.Get(key).IsString() ? v.Get(key).Get<std::string>() : fallback;
}

/// One meshopt-compressed buffer view into a new buffer; empty, or why not.
std::string decode_meshopt_view(tinygltf::Model& m, std::size_t vi, const tinygltf::Value& ext) {
  std::uint64_t buffer = 0, offset = 0, length = 0, stride = 0, count = 0;
  if (!get_uint(ext, "buffer", buffer) || !get_uint(ext, "byteLength", length) || !get_uint(ext, "byteStride", stride) ||
      !get_uint(ext, "count", count))
    return "its buffer, byteLength, byteStride or count is missing or not a whole number";
  get_uint(ext, "byteOffset", offset);
  if (buffer >= m.buffers.size()) return "its buffer index is out of range";
  const std::vector<unsigned char>& src = m.buffers[buffer].data;
  if (offset > src.size() || length > src.size() - offset) return "its compressed bytes reach past the end of the buffer";
  if (stride == 0 || stride > 256 || count > kMaxDecoded / stride) return "its byteStride or count is out of range";
  const std::string mode = get_string(ext, "mode", "");
  const std::string filter = get_string(ext, "filter", "NONE");
  std::vector<unsigned char> out(static_cast<std::size_t>(count * stride));
  const unsigned char* in = src.data() + offset;
  const std::size_t n = static_cast<std::size_t>(count), s = static_cast<std::size_t>(stride), len = static_cast<std::size_t>(length);
  int rc = 0;
  if (mode == "ATTRIBUTES") {
    if (s % 4 != 0) return "ATTRIBUTES with a byteStride that is not a multiple of 4";
    rc = meshopt_decodeVertexBuffer(out.data(), n, s, in, len);
    if (rc == 0) {
      if (filter == "OCTAHEDRAL" && (s == 4 || s == 8)) meshopt_decodeFilterOct(out.data(), n, s);
      else if (filter == "QUATERNION" && s == 8) meshopt_decodeFilterQuat(out.data(), n, s);
      else if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), n, s);
      else if (filter != "NONE") return "filter \"" + filter + "\" with byteStride " + std::to_string(s) + " is not supported";
    }
  } else if (mode == "TRIANGLES" || mode == "INDICES") {
    if (s != 2 && s != 4) return mode + " with a byteStride other than 2 or 4";
    if (mode == "TRIANGLES" && n % 3 != 0) return "TRIANGLES with a count that is not a multiple of 3";
    rc = mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), n, s, in, len)
                             : meshopt_decodeIndexSequence(out.data(), n, s, in, len);
  } else {
    return "mode \"" + mode + "\" is not ATTRIBUTES, TRIANGLES or INDICES";
  }
  if (rc != 0) {
    // The vertex codec's version is the high nibble's low bits of its first byte (0xa0: version 0).
    if (mode == "ATTRIBUTES" && len > 0 && (in[0] & 0xf0) == 0xa0 && (in[0] & 0x0f) != 0)
      return "its vertex data use meshopt codec version " + std::to_string(in[0] & 0x0f) +
             ", which this build's meshoptimizer (" + std::to_string(MESHOPTIMIZER_VERSION / 1000) + "." +
             std::to_string(MESHOPTIMIZER_VERSION % 1000 / 10) + ") cannot decode";
    return "the meshopt decoder refused its bytes (error " + std::to_string(rc) + ")";
  }
  tinygltf::Buffer decoded;
  decoded.data = std::move(out);
  m.buffers.push_back(std::move(decoded));
  tinygltf::BufferView& view = m.bufferViews[vi];
  view.buffer = static_cast<int>(m.buffers.size() - 1);
  view.byteOffset = 0;
  view.byteLength = static_cast<std::size_t>(count * stride);
  if (mode == "ATTRIBUTES") view.byteStride = s;
  return {};
}

/// A new buffer + view + accessor holding `bytes`; returns the accessor's index.
int add_accessor(tinygltf::Model& m, std::vector<unsigned char>&& bytes, int component, int type, std::size_t count) {
  tinygltf::Buffer b;
  b.data = std::move(bytes);
  const std::size_t length = b.data.size();
  m.buffers.push_back(std::move(b));
  tinygltf::BufferView v;
  v.buffer = static_cast<int>(m.buffers.size() - 1);
  v.byteOffset = 0;
  v.byteLength = length;
  m.bufferViews.push_back(std::move(v));
  tinygltf::Accessor a;
  a.bufferView = static_cast<int>(m.bufferViews.size() - 1);
  a.componentType = component;
  a.type = type;
  a.count = count;
  m.accessors.push_back(std::move(a));
  return static_cast<int>(m.accessors.size() - 1);
}

/// One Draco primitive into plain accessors; empty, or why not.
std::string decode_draco_primitive(tinygltf::Model& m, tinygltf::Primitive& pr, const tinygltf::Value& ext) {
  std::uint64_t vi = 0;
  if (!get_uint(ext, "bufferView", vi) || vi >= m.bufferViews.size()) return "its bufferView is missing or out of range";
  if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) return "it has no \"attributes\" object";
  const tinygltf::BufferView& view = m.bufferViews[vi];
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= m.buffers.size()) return "its buffer is out of range";
  const std::vector<unsigned char>& src = m.buffers[static_cast<std::size_t>(view.buffer)].data;
  if (view.byteOffset > src.size() || view.byteLength > src.size() - view.byteOffset)
    return "its bufferView reaches past the end of its buffer";
  draco::DecoderBuffer in;
  in.Init(reinterpret_cast<const char*>(src.data() + view.byteOffset), view.byteLength);
  const auto type = draco::Decoder::GetEncodedGeometryType(&in);
  if (!type.ok() || type.value() != draco::TRIANGULAR_MESH) return "its Draco data is not a triangle mesh";
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) return "the Draco decoder refused it: " + decoded.status().error_msg_string();
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  const std::size_t points = mesh->num_points(), faces = mesh->num_faces();
  if (faces > kMaxDecoded / 12 || points > kMaxDecoded / 16) return "it decodes to too many points or faces";
  std::vector<unsigned char> idx(faces * 12);
  for (std::size_t f = 0; f < faces; ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(static_cast<std::uint32_t>(f)));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = face[k].value();
      if (v >= points) return "a Draco face refers to a point out of range";
      std::memcpy(idx.data() + f * 12 + static_cast<std::size_t>(k) * 4, &v, 4);
    }
  }
  std::map<std::string, int> attributes;
  for (const std::string& name : ext.Get("attributes").Keys()) {
    const tinygltf::Value& id = ext.Get("attributes").Get(name);
    if (!id.IsNumber()) return "Draco attribute " + name + " has no unique id";
    const double d = id.GetNumberAsDouble();
    if (!(d >= 0) || d > 1e9) return "Draco attribute " + name + " has an id out of range";
    const draco::PointAttribute* a = mesh->GetAttributeByUniqueId(static_cast<std::uint32_t>(d));
    if (!a) return "Draco attribute " + name + " is not in the Draco data";
    const int n = a->num_components();
    if (n < 1 || n > 4) return "Draco attribute " + name + " has " + std::to_string(n) + " components";
    std::vector<unsigned char> bytes(points * static_cast<std::size_t>(n) * 4);
    float value[4];
    for (std::size_t p = 0; p < points; ++p) {
      if (!a->ConvertValue<float>(a->mapped_index(draco::PointIndex(static_cast<std::uint32_t>(p))),
                                  static_cast<std::int8_t>(n), value))
        return "Draco attribute " + name + " cannot be read as numbers";
      std::memcpy(bytes.data() + p * static_cast<std::size_t>(n) * 4, value, static_cast<std::size_t>(n) * 4);
    }
    const int types[] = {TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
    attributes[name] = add_accessor(m, std::move(bytes), TINYGLTF_COMPONENT_TYPE_FLOAT, types[n - 1], points);
  }
  for (const auto& [name, accessor] : attributes) pr.attributes[name] = accessor;
  pr.indices = add_accessor(m, std::move(idx), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, faces * 3);
  return {};
}

}  // namespace

std::string loadable_json(std::string_view text) {
  if (text.find(kDraco) == std::string_view::npos && text.find("meshopt_compression") == std::string_view::npos)
    return {};
  nlohmann::json j = nlohmann::json::parse(text.begin(), text.end());  // throws on bad JSON
  bool changed = false;
  if (j.is_object() && j.contains("meshes") && j["meshes"].is_array())
    for (auto& mesh : j["meshes"])
      if (mesh.is_object() && mesh.contains("primitives") && mesh["primitives"].is_array())
        for (auto& pr : mesh["primitives"])
          if (pr.is_object() && pr.contains("extensions") && pr["extensions"].is_object() &&
              pr["extensions"].contains(kDraco) && pr.contains("indices")) {
            pr.erase("indices");
            changed = true;
          }
  if (j.is_object() && j.contains("buffers") && j["buffers"].is_array())
    for (auto& b : j["buffers"]) {
      if (!b.is_object() || !b.contains("extensions") || !b["extensions"].is_object()) continue;
      for (const char* name : {kMeshoptExt, kMeshoptKhr}) {
        const auto& e = b["extensions"];
        if (e.contains(name) && e[name].is_object() && e[name].value("fallback", false) && !b.contains("uri")) {
          b = nlohmann::json{{"byteLength", 1}, {"uri", "data:application/octet-stream;base64,AA=="}};
          changed = true;
          break;
        }
      }
    }
  return changed ? j.dump() : std::string();
}

std::vector<std::string> unknown_required_extensions(const tinygltf::Model& model) {
  std::vector<std::string> out;
  for (const std::string& e : model.extensionsRequired) {
    const bool known = e == kDraco || e == kMeshoptExt || e == kMeshoptKhr || e == "KHR_mesh_quantization" ||
                       e == "CESIUM_RTC" || e == "EXT_mesh_features" || e == "EXT_structural_metadata" ||
                       e == "EXT_mesh_gpu_instancing" || e == "EXT_instance_features" ||
                       starts_with(e, "KHR_materials_") || starts_with(e, "KHR_texture_") ||
                       starts_with(e, "EXT_texture_");
    if (!known) out.push_back(e);
  }
  return out;
}

void decode(tinygltf::Model& model, std::vector<std::string>& problems) {
  const std::size_t views = model.bufferViews.size();
  for (std::size_t vi = 0; vi < views; ++vi)
    if (const tinygltf::Value* ext = meshopt_of(model.bufferViews[vi].extensions)) {
      const std::string why = decode_meshopt_view(model, vi, *ext);
      if (!why.empty()) {
        problems.push_back("meshopt-compressed bufferView " + std::to_string(vi) + " is not read: " + why);
        model.bufferViews[vi].buffer = -1;  // unreadable: the reader says which primitive it spoils
      }
    }
  for (std::size_t mi = 0; mi < model.meshes.size(); ++mi)
    for (tinygltf::Primitive& pr : model.meshes[mi].primitives) {
      auto ext = pr.extensions.find(kDraco);
      if (ext == pr.extensions.end()) continue;
      const std::string why = decode_draco_primitive(model, pr, ext->second);
      if (!why.empty()) {
        problems.push_back("a Draco-compressed primitive of mesh " + std::to_string(mi) + " is not read: " + why);
        pr.attributes.clear();  // the reader skips it ("no POSITION"): the line above says why
      } else {
        pr.extensions.erase(ext);
      }
    }
}

}  // namespace groundplan::gis::gltf

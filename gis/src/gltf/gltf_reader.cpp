// SPDX-License-Identifier: MIT
// glTF 2.0 / GLB reader (issue 6). tinygltf parses the JSON and loads buffers; everything it hands
// back is treated as untrusted: accessor, buffer view and buffer bounds, strides and indices are
// checked here before a byte is read.
#include <groundplan/error.h>
#include <groundplan/gis/gltf.h>

#include "collada/collada_internal.h"
#include "files_read.h"
#include "xml/safe_xml.h"

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <cpl_vsi.h>

#include "gltf/gltf_extensions.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;
using detail::Mat4;

constexpr int kTriangles = 4, kTriangleStrip = 5, kTriangleFan = 6;
constexpr int kFloat = 5126, kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123, kUInt = 5125;
constexpr double kEarthMin = 6.2e6, kEarthMax = 6.5e6;  // |ECEF| of anything on the ground, in metres

/// What the fs callbacks may touch: files under `root`, within `budget`.
struct FsGuard {
  fs::path root;       // canonical folder of the glTF
  bool vsi = false;    // the input is a VSI path: no canonical check, lexical only
  xml::ByteBudget* budget = nullptr;
  std::string refused; // the first path refused, for the message
};

bool inside(const FsGuard& g, const std::string& path) {
  std::error_code ec;
  if (g.vsi) {
    const std::string rel = path.substr(0, g.root.string().size()) == g.root.string()
                                ? path.substr(g.root.string().size())
                                : std::string("/..");
    return rel.find("/..") == std::string::npos && rel.find("\\") == std::string::npos;
  }
  const fs::path t = fs::weakly_canonical(path, ec);
  if (ec) return false;
  auto r = g.root.begin();
  auto p = t.begin();
  for (; r != g.root.end(); ++r, ++p)
    if (p == t.end() || *r != *p) return false;
  return true;
}

bool fs_exists(const std::string& path, void* ud) {
  auto* g = static_cast<FsGuard*>(ud);
  if (!inside(*g, path)) {
    if (g->refused.empty()) g->refused = path;
    return false;
  }
  note_file_opened(path);  // a buffer looked for: the result depends on it, there or not
  VSIStatBufL st;
  return VSIStatL(path.c_str(), &st) == 0;
}

std::string fs_expand(const std::string& path, void*) { return path; }  // no ~ or $VAR expansion

bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* ud) {
  auto* g = static_cast<FsGuard*>(ud);
  if (!inside(*g, path)) {
    if (g->refused.empty()) g->refused = path;
    if (err) *err += "refused to read " + path + ": outside the glTF's folder\n";
    return false;
  }
  try {
    const std::string data = xml::read_vsi_file(path, path, *g->budget);
    out->assign(data.begin(), data.end());
    return true;
  } catch (const std::exception& e) {
    if (err) *err += std::string(e.what()) + "\n";
    return false;
  }
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is disabled\n";
  return false;
}

bool no_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;  // geometry only: images are neither decoded nor kept
}

Mat4 node_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) {
    Mat4 m;  // glTF matrices are column-major
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[r * 4 + c] = n.matrix[c * 4 + r];
    return m;
  }
  Mat4 m = detail::kIdentity;
  if (n.translation.size() == 3) m = detail::translation(n.translation[0], n.translation[1], n.translation[2]);
  if (n.rotation.size() == 4) {
    double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
    const double len = std::sqrt(x * x + y * y + z * z + w * w);
    if (len > 0) x /= len, y /= len, z /= len, w /= len;
    const Mat4 r = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),     0,
                    2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),     0,
                    2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y), 0,
                    0,                       0,                       0,                       1};
    m = detail::multiply(m, r);
  }
  if (n.scale.size() == 3) m = detail::multiply(m, detail::scaling(n.scale[0], n.scale[1], n.scale[2]));
  return m;
}

bool finite(const Mat4& m) {
  for (double v : m)
    if (!std::isfinite(v)) return false;
  return true;
}

/// One element's component as a number: glTF's component types, normalized integers scaled to [-1, 1] / [0, 1].
double component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case kFloat: { float f; std::memcpy(&f, p, 4); return f; }
    case kUByte: return normalized ? *p / 255.0 : *p;
    case kByte: { const auto v = static_cast<std::int8_t>(*p); return normalized ? std::max(v / 127.0, -1.0) : v; }
    case kUShort: { std::uint16_t v; std::memcpy(&v, p, 2); return normalized ? v / 65535.0 : v; }
    case kShort: { std::int16_t v; std::memcpy(&v, p, 2); return normalized ? std::max(v / 32767.0, -1.0) : v; }
    case kUInt: { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::size_t component_size(int type) {
  switch (type) {
    case kByte: case kUByte: return 1;
    case kShort: case kUShort: return 2;
    case kUInt: case kFloat: return 4;
  }
  return 0;
}

/// The feature ids of a primitive: which attribute holds them, and the property table that names them.
struct FeatureIdSet {
  int accessor = -1;        // accessor of the per-vertex ids; -1: none
  int property_table = -1;  // EXT_structural_metadata property table; -1: none
  double null_id = std::numeric_limits<double>::quiet_NaN();
};

constexpr int kWholeModel = -2;  // feature_mesh's "table" of GltfTile::building: the whole model is one building

class Reader {
 public:
  Reader(const std::string& path, const GltfOptions& opt, const GltfTile* tile, const GltfMeshCallback& cb,
         std::vector<Problem>& problems, GltfInfo& info, tinygltf::Model& model)
      : path_(path), opt_(opt), tile_(tile), cb_(cb), problems_(problems), info_(info), m_(model) {}

  void run() {
    // CESIUM_RTC: positions are relative to an ECEF centre (after the y-up -> z-up turn).
    auto rtc = m_.extensions.find("CESIUM_RTC");
    if (rtc != m_.extensions.end()) {
      const tinygltf::Value& c = rtc->second.Get("center");
      if (c.IsArray() && c.ArrayLen() == 3 && c.Get(0).IsNumber() && c.Get(1).IsNumber() && c.Get(2).IsNumber()) {
        rtc_ = {c.Get(0).GetNumberAsDouble(), c.Get(1).GetNumberAsDouble(), c.Get(2).GetNumberAsDouble()};
        has_rtc_ = std::isfinite(rtc_.x) && std::isfinite(rtc_.y) && std::isfinite(rtc_.z);
        if (has_rtc_) info_.georeference = "CESIUM_RTC";
      }
      if (!has_rtc_) problem("", "BAD_GEOREFERENCE", "CESIUM_RTC has no usable \"center\" [x, y, z]: ignored");
    }
    if (tile_ && tile_->has_rtc_center) {  // a b3dm's RTC_CENTER: the same, from the tile's feature table
      rtc_ = tile_->rtc_center;
      has_rtc_ = true;
      info_.georeference = "RTC_CENTER";
    }
    // glTF is y-up; 3D Tiles and we are z-up: (x, y, z) -> (x, -z, y). Then the RTC centre, then the tile's
    // transform (3D Tiles: tile transform * RTC * y-up to z-up * node transforms).
    const Mat4 y_up_to_z_up = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1};
    Mat4 root = y_up_to_z_up;
    if (has_rtc_) root = detail::multiply(detail::translation(rtc_.x, rtc_.y, rtc_.z), root);
    if (tile_) root = detail::multiply(tile_->transform, root);
    std::vector<int> roots;
    const int scene = m_.defaultScene >= 0 ? m_.defaultScene : (m_.scenes.empty() ? -1 : 0);
    if (scene >= 0 && static_cast<std::size_t>(scene) < m_.scenes.size()) {
      roots = m_.scenes[static_cast<std::size_t>(scene)].nodes;
    } else {
      std::vector<bool> child(m_.nodes.size(), false);
      for (const auto& n : m_.nodes)
        for (int c : n.children)
          if (c >= 0 && static_cast<std::size_t>(c) < child.size()) child[static_cast<std::size_t>(c)] = true;
      for (std::size_t i = 0; i < m_.nodes.size(); ++i)
        if (!child[i]) roots.push_back(static_cast<int>(i));
    }
    on_stack_.assign(m_.nodes.size(), false);
    for (int r : roots) visit(r, root, 0, std::string());
    // Buildings by feature: delivered once the whole glTF is read (a feature may span nodes and primitives).
    for (std::size_t k = 0; k < feature_order_.size(); ++k) deliver(std::move(features_[feature_order_[k]]));
    if (!feature_order_.empty() || by_instance_) info_.by_feature = true;
    if (info_.meshes == 0) problem("", "NO_GEOMETRY", "the glTF scene holds no triangle geometry");
    else if (tile_ && feature_order_.empty() && !by_instance_ && info_.meshes > 0)
      problem("", "NOTE", "no feature ids (_BATCHID, EXT_mesh_features): one building per glTF node with a mesh");
  }

 private:
  void problem(const std::string& id, const std::string& code, const std::string& reason) {
    problems_.push_back(Problem{id, path_, "read", code, reason});
  }

  /// `named`: the name of the nearest named ancestor, which a mesh node without a name of its own takes
  /// (gltfpack -kn keeps a named node and hangs the mesh under it).
  void visit(int index, const Mat4& parent, int depth, const std::string& named) {
    if (index < 0 || static_cast<std::size_t>(index) >= m_.nodes.size()) {
      problem("", "BAD_REFERENCE", "node index " + std::to_string(index) + " is out of range");
      return;
    }
    const std::size_t i = static_cast<std::size_t>(index);
    if (on_stack_[i] || depth > opt_.max_node_depth) {
      problem("", "NODE_CYCLE", "node " + std::to_string(index) + " is its own ancestor or nested deeper than " +
                                    std::to_string(opt_.max_node_depth) + " levels: not followed");
      return;
    }
    on_stack_[i] = true;
    ++info_.nodes;
    const tinygltf::Node& n = m_.nodes[i];
    const Mat4 world = detail::multiply(parent, node_matrix(n));
    const std::string& name = n.name.empty() ? named : n.name;
    // An unnamed node in a tile is named after the tile too: "node N" alone repeats in every tile.
    const std::string unnamed = (tile_ ? tile_->feature_prefix + " " : std::string()) + "node " + std::to_string(index);
    if (n.mesh >= 0) emit(name.empty() ? unnamed : name, n, world);
    for (int c : n.children) visit(c, world, depth + 1, name);
    on_stack_[i] = false;
  }

  /// The bytes of an accessor's elements: base pointer, stride and count, all checked.
  bool view(const tinygltf::Accessor& a, std::size_t elem_size, const unsigned char*& base, std::size_t& stride,
            std::string& why) const {
    if (a.sparse.isSparse) return why = "sparse accessors are not supported", false;
    if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= m_.bufferViews.size())
      return why = "accessor's bufferView is out of range", false;
    const tinygltf::BufferView& bv = m_.bufferViews[static_cast<std::size_t>(a.bufferView)];
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= m_.buffers.size())
      return why = "bufferView's buffer is out of range (or its compressed data could not be decoded)", false;
    const std::vector<unsigned char>& data = m_.buffers[static_cast<std::size_t>(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
      return why = "bufferView reaches past the end of its buffer", false;
    stride = bv.byteStride ? bv.byteStride : elem_size;
    if (stride < elem_size) return why = "bufferView's byteStride is smaller than an element", false;
    if (a.count == 0) {
      base = nullptr;
      return true;
    }
    if (a.byteOffset > bv.byteLength) return why = "accessor's byteOffset is past its bufferView", false;
    const std::size_t avail = bv.byteLength - a.byteOffset;
    if (a.count - 1 > (avail - std::min(avail, elem_size)) / stride || avail < elem_size)
      return why = "accessor's count reaches past the end of its bufferView", false;
    base = data.data() + bv.byteOffset + a.byteOffset;
    return true;
  }

  /// The feature id set a primitive's buildings are split by: EXT_mesh_features (the first set with a
  /// property table, else the first by attribute), else 3D Tiles 1.0's _BATCHID.
  FeatureIdSet feature_ids(const tinygltf::Primitive& pr) const {
    FeatureIdSet out;
    auto ext = pr.extensions.find("EXT_mesh_features");
    if (ext != pr.extensions.end() && ext->second.Get("featureIds").IsArray()) {
      const tinygltf::Value& sets = ext->second.Get("featureIds");
      for (int pass = 0; pass < 2 && out.accessor < 0; ++pass)
        for (std::size_t k = 0; k < sets.ArrayLen(); ++k) {
          const tinygltf::Value& s = sets.Get(static_cast<int>(k));
          if (!s.Get("attribute").IsNumber()) continue;  // by texture or implicit (index): not by vertex
          const bool table = s.Get("propertyTable").IsNumber();
          if (pass == 0 && !table) continue;
          auto attr = pr.attributes.find("_FEATURE_ID_" + std::to_string(s.Get("attribute").GetNumberAsInt()));
          if (attr == pr.attributes.end()) continue;
          out.accessor = attr->second;
          out.property_table = table ? s.Get("propertyTable").GetNumberAsInt() : -1;
          if (s.Get("nullFeatureId").IsNumber()) out.null_id = s.Get("nullFeatureId").GetNumberAsDouble();
          break;
        }
    }
    if (out.accessor < 0) {
      auto b = pr.attributes.find("_BATCHID");
      if (b == pr.attributes.end()) b = pr.attributes.find("BATCHID");
      if (b != pr.attributes.end()) out.accessor = b->second;
    }
    return out;
  }

  /// A string property of an EXT_structural_metadata property table row; empty when there is none.
  std::string table_string(int table, std::int64_t row) const {
    auto ext = m_.extensions.find("EXT_structural_metadata");
    if (ext == m_.extensions.end() || row < 0) return {};
    const tinygltf::Value& tables = ext->second.Get("propertyTables");
    if (!tables.IsArray() || table < 0 || static_cast<std::size_t>(table) >= tables.ArrayLen()) return {};
    const tinygltf::Value& t = tables.Get(table);
    if (!t.Get("count").IsNumber() || row >= t.Get("count").GetNumberAsInt()) return {};
    const tinygltf::Value& props = t.Get("properties");
    if (!props.IsObject()) return {};
    for (const std::string& name : id_fields()) {
      if (!props.Has(name)) continue;
      const tinygltf::Value& p = props.Get(name);
      if (!p.Get("values").IsNumber() || !p.Get("stringOffsets").IsNumber()) continue;  // strings only
      const std::string offset_type = p.Get("stringOffsetType").IsString() ? p.Get("stringOffsetType").Get<std::string>() : "UINT32";
      const std::size_t osize = offset_type == "UINT8" ? 1 : offset_type == "UINT16" ? 2 : offset_type == "UINT32" ? 4 : offset_type == "UINT64" ? 8 : 0;
      const std::vector<unsigned char>* values = view_bytes(p.Get("values").GetNumberAsInt());
      const std::vector<unsigned char>* offsets = view_bytes(p.Get("stringOffsets").GetNumberAsInt());
      if (!values || !offsets || osize == 0) continue;
      const std::size_t r = static_cast<std::size_t>(row);
      if ((r + 2) * osize > offsets->size()) continue;
      auto at = [&](std::size_t k) {
        std::uint64_t v = 0;
        std::memcpy(&v, offsets->data() + k * osize, osize);  // little-endian
        return v;
      };
      const std::uint64_t a = at(r), b = at(r + 1);
      if (a > b || b > values->size()) continue;
      return std::string(reinterpret_cast<const char*>(values->data() + a), static_cast<std::size_t>(b - a));
    }
    return {};
  }

  std::vector<std::string> id_fields() const {
    if (!opt_.id_field.empty()) return {opt_.id_field};
    return {"gml_id", "id", "name"};
  }

  /// A whole buffer view's bytes (a copy only of the view, not of its buffer); nullptr when out of range.
  const std::vector<unsigned char>* view_bytes(int index) const {
    if (index < 0 || static_cast<std::size_t>(index) >= m_.bufferViews.size()) return nullptr;
    auto& cached = view_cache_[index];
    if (!cached.empty() || checked_views_.count(index)) return &cached;
    checked_views_.insert(index);
    const tinygltf::BufferView& bv = m_.bufferViews[static_cast<std::size_t>(index)];
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= m_.buffers.size()) return nullptr;
    const std::vector<unsigned char>& data = m_.buffers[static_cast<std::size_t>(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset) return nullptr;
    cached.assign(data.begin() + static_cast<std::ptrdiff_t>(bv.byteOffset),
                  data.begin() + static_cast<std::ptrdiff_t>(bv.byteOffset + bv.byteLength));
    return &cached;
  }

  /// The building a feature id gives: its id from the property table / batch table, else "<prefix>#<id>".
  Mesh& feature_mesh(std::int64_t id, int table, const std::string& node_id) {
    const std::string key = std::to_string(table) + ":" + std::to_string(id);
    auto it = features_.find(key);
    if (it != features_.end()) return it->second;
    std::string name = table == kWholeModel ? tile_->building : table >= 0 ? table_string(table, id) : std::string();
    if (name.empty() && tile_ && tile_->feature_name) name = tile_->feature_name(id);
    if (name.empty()) name = (tile_ ? tile_->feature_prefix : std::string("feature ")) + "#" + std::to_string(id);
    if (id < 0 && table != kWholeModel) name = node_id + " (no feature id)";
    Mesh& mesh = features_[key];
    mesh.source_id = name;
    mesh.source_file = path_;
    feature_order_.push_back(key);
    return mesh;
  }

  void emit(const std::string& id, const tinygltf::Node& n, const Mat4& world) {
    if (static_cast<std::size_t>(n.mesh) >= m_.meshes.size()) {
      problem(id, "BAD_REFERENCE", "the node's mesh index " + std::to_string(n.mesh) + " is out of range");
      return;
    }
    if (!finite(world)) {
      problem(id, "BAD_TRANSFORM", "the node's transform holds NaN or infinity");
      return;
    }
    if (instanced(id, n, world)) return;
    Mesh mesh;
    mesh.source_id = id;
    mesh.name = m_.meshes[static_cast<std::size_t>(n.mesh)].name;
    mesh.source_file = path_;
    for (const tinygltf::Primitive& pr : m_.meshes[static_cast<std::size_t>(n.mesh)].primitives) {
      std::string why;
      if (!primitive(pr, world, mesh, id, why)) problem(id, "BAD_PRIMITIVE", "a primitive is skipped: " + why);
      if (stopped_) break;
    }
    deliver(std::move(mesh));
  }

  /// EXT_mesh_gpu_instancing: the node's mesh once per instance (TRANSLATION, ROTATION, SCALE in the node's
  /// frame), each instance one building, named by its EXT_instance_features id in the property table, else
  /// "<node> #<instance>". False when the node is not instanced.
  bool instanced(const std::string& id, const tinygltf::Node& n, const Mat4& world) {
    auto ext = n.extensions.find("EXT_mesh_gpu_instancing");
    if (ext == n.extensions.end()) return false;
    const tinygltf::Value& attrs = ext->second.Get("attributes");
    struct Attr {
      const unsigned char* base = nullptr;
      std::size_t stride = 0, size = 0;
      int type = 0;
      bool normalized = false, present = false;
      double at(std::size_t i, int k) const { return component(base + i * stride + static_cast<std::size_t>(k) * size, type, normalized); }
    };
    std::size_t count = 0;
    bool counted = false;
    auto get = [&](const std::string& name, int width, Attr& out) -> std::string {
      if (!attrs.IsObject() || !attrs.Has(name)) return {};
      const tinygltf::Value& v = attrs.Get(name);
      const int ai = v.IsNumber() ? v.GetNumberAsInt() : -1;
      if (ai < 0 || static_cast<std::size_t>(ai) >= m_.accessors.size()) return name + ": accessor index out of range";
      const tinygltf::Accessor& a = m_.accessors[static_cast<std::size_t>(ai)];
      const int want = width == 1 ? TINYGLTF_TYPE_SCALAR : width == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
      out.size = component_size(a.componentType);
      if (a.type != want || out.size == 0) return name + " is not of the type the extension says";
      std::string why;
      if (!view(a, out.size * static_cast<std::size_t>(width), out.base, out.stride, why)) return name + ": " + why;
      if (counted && a.count != count) return "its attributes differ in count";
      count = a.count, counted = true, out.type = a.componentType, out.normalized = a.normalized, out.present = true;
      return {};
    };
    Attr t, r, sc, fid;
    int table = -1;
    std::string why = get("TRANSLATION", 3, t);
    if (why.empty()) why = get("ROTATION", 4, r);
    if (why.empty()) why = get("SCALE", 3, sc);
    auto features = n.extensions.find("EXT_instance_features");
    if (why.empty() && features != n.extensions.end() && features->second.Get("featureIds").IsArray() &&
        features->second.Get("featureIds").ArrayLen() > 0) {
      const tinygltf::Value& set = features->second.Get("featureIds").Get(0);
      if (set.Get("attribute").IsNumber()) why = get("_FEATURE_ID_" + std::to_string(set.Get("attribute").GetNumberAsInt()), 1, fid);
      if (set.Get("propertyTable").IsNumber()) table = set.Get("propertyTable").GetNumberAsInt();
    }
    if (!why.empty()) {
      problem(id, "BAD_PRIMITIVE", "EXT_mesh_gpu_instancing: " + why + ": the node's instances are skipped");
      return true;
    }
    const tinygltf::Mesh& gm = m_.meshes[static_cast<std::size_t>(n.mesh)];
    for (std::size_t i = 0; i < count && !stopped_; ++i) {
      tinygltf::Node place;  // the instance's TRS, turned into a matrix as a node's is
      if (t.present) place.translation = {t.at(i, 0), t.at(i, 1), t.at(i, 2)};
      if (r.present) place.rotation = {r.at(i, 0), r.at(i, 1), r.at(i, 2), r.at(i, 3)};
      if (sc.present) place.scale = {sc.at(i, 0), sc.at(i, 1), sc.at(i, 2)};
      const Mat4 m = detail::multiply(world, node_matrix(place));
      const double f = fid.present ? fid.at(i, 0) : -1;
      std::string name = f >= 0 && table >= 0 ? table_string(table, static_cast<std::int64_t>(f)) : std::string();
      if (name.empty()) name = id + " #" + std::to_string(i);
      if (!finite(m)) {
        problem(name, "BAD_TRANSFORM", "the instance's transform holds NaN or infinity");
        continue;
      }
      Mesh mesh;
      mesh.source_id = name;
      mesh.name = gm.name;
      mesh.source_file = path_;
      instancing_ = true;  // the mesh's own feature ids would join the instances: one building an instance
      for (const tinygltf::Primitive& pr : gm.primitives) {
        std::string bad;
        if (!primitive(pr, m, mesh, name, bad)) problem(name, "BAD_PRIMITIVE", "a primitive is skipped: " + bad);
        if (stopped_) break;
      }
      instancing_ = false;
      if (!mesh.faces.empty()) by_instance_ = true;
      deliver(std::move(mesh));
    }
    return true;
  }

  void deliver(Mesh&& mesh) {
    if (mesh.faces.empty()) return;
    // The frame: ECEF when an RTC centre or a tile says so or the positions sit at the Earth's radius.
    GltfFrame frame = GltfFrame::Local;
    const Point3& p = mesh.vertices.front();
    const double r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    if (has_rtc_ || (r > kEarthMin && r < kEarthMax)) {
      frame = GltfFrame::Ecef;
      if (info_.georeference.empty()) info_.georeference = tile_ ? "3D Tiles transform" : "ECEF node transform";
    }
    ++info_.meshes;
    cb_(std::move(mesh), frame);
  }

  bool primitive(const tinygltf::Primitive& pr, const Mat4& world, Mesh& node_mesh, const std::string& node_id,
                 std::string& why) {
    if (pr.mode != kTriangles && pr.mode != kTriangleStrip && pr.mode != kTriangleFan) return true;  // points, lines
    if (pr.extensions.count("KHR_draco_mesh_compression")) return true;  // not decoded: gltf::decode said why
    auto pos = pr.attributes.find("POSITION");
    if (pos == pr.attributes.end()) return why = "no POSITION attribute", false;
    if (pos->second < 0 || static_cast<std::size_t>(pos->second) >= m_.accessors.size())
      return why = "POSITION accessor index is out of range", false;
    const tinygltf::Accessor& pa = m_.accessors[static_cast<std::size_t>(pos->second)];
    const std::size_t psize = component_size(pa.componentType);
    if (pa.type != TINYGLTF_TYPE_VEC3 || psize == 0 || (pa.componentType == kUInt))
      return why = "POSITION is not VEC3 of FLOAT, or of (normalized) BYTE or SHORT (KHR_mesh_quantization)", false;
    const unsigned char* pbase = nullptr;
    std::size_t pstride = 0;
    if (!view(pa, 3 * psize, pbase, pstride, why)) return why = "POSITION: " + why, false;
    if (total_vertices_ + pa.count > opt_.max_vertices) {
      stopped_ = true;
      return why = "the file holds more than " + std::to_string(opt_.max_vertices) + " vertices: the rest is not read",
             false;
    }
    // Indices first: nothing is appended unless the whole primitive is sound.
    std::vector<std::uint32_t> idx;
    if (pr.indices >= 0) {
      if (static_cast<std::size_t>(pr.indices) >= m_.accessors.size()) return why = "indices accessor is out of range", false;
      const tinygltf::Accessor& ia = m_.accessors[static_cast<std::size_t>(pr.indices)];
      const std::size_t size = ia.componentType == kUByte ? 1 : ia.componentType == kUShort ? 2 : ia.componentType == kUInt ? 4 : 0;
      if (ia.type != TINYGLTF_TYPE_SCALAR || size == 0) return why = "indices are not SCALAR unsigned integers", false;
      const unsigned char* ibase = nullptr;
      std::size_t istride = 0;
      if (!view(ia, size, ibase, istride, why)) return why = "indices: " + why, false;
      idx.resize(ia.count);
      for (std::size_t k = 0; k < ia.count; ++k) {
        const auto v = static_cast<std::uint32_t>(component(ibase + k * istride, ia.componentType, false));
        if (v >= pa.count) return why = "index " + std::to_string(v) + " is out of range (" + std::to_string(pa.count) + " positions)", false;
        idx[k] = v;
      }
    } else {
      idx.resize(pa.count);
      for (std::size_t k = 0; k < pa.count; ++k) idx[k] = static_cast<std::uint32_t>(k);
    }
    // Feature ids, one per vertex: the primitive's triangles go to the building of their first vertex.
    const FeatureIdSet fs = instancing_ ? FeatureIdSet{} : feature_ids(pr);
    std::vector<std::int64_t> fid;
    if (fs.accessor >= 0) {
      if (static_cast<std::size_t>(fs.accessor) >= m_.accessors.size()) return why = "feature id accessor is out of range", false;
      const tinygltf::Accessor& fa = m_.accessors[static_cast<std::size_t>(fs.accessor)];
      const std::size_t fsize = component_size(fa.componentType);
      if (fa.type != TINYGLTF_TYPE_SCALAR || fsize == 0 || fa.count != pa.count)
        return why = "feature ids are not one SCALAR number per position", false;
      const unsigned char* fbase = nullptr;
      std::size_t fstride = 0;
      if (!view(fa, fsize, fbase, fstride, why)) return why = "feature ids: " + why, false;
      fid.resize(fa.count);
      for (std::size_t k = 0; k < fa.count; ++k) {
        const double v = component(fbase + k * fstride, fa.componentType, false);
        // A feature id is a whole number >= 0 (float ids are exact up to 2^24); else, or null: no feature (-1).
        fid[k] = std::isfinite(v) && v >= 0 && v < 16777216.0 && v == std::floor(v) && v != fs.null_id
                     ? static_cast<std::int64_t>(v) : -1;
      }
    }
    std::vector<Point3> placed(pa.count);
    for (std::size_t k = 0; k < pa.count; ++k) {
      const unsigned char* e = pbase + k * pstride;
      const double x = component(e, pa.componentType, pa.normalized), y = component(e + psize, pa.componentType, pa.normalized),
                   z = component(e + 2 * psize, pa.componentType, pa.normalized);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return why = "a position is NaN or infinite", false;
      placed[k] = detail::apply(world, Point3{x, y, z});
    }
    total_vertices_ += pa.count;
    // Where each vertex went in the mesh of its building (UINT32_MAX: not yet).
    std::vector<std::uint32_t> at(pa.count, UINT32_MAX);
    std::vector<Mesh*> in(pa.count, nullptr);
    auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      Mesh& mesh = tile_ && !tile_->building.empty() ? feature_mesh(0, kWholeModel, node_id)
                   : fid.empty()                           ? node_mesh
                                                           : feature_mesh(fid[a], fs.property_table, node_id);
      for (std::uint32_t v : {a, b, c}) {
        if (in[v] != &mesh) {  // first time in this building's mesh (a vertex of two features is copied)
          in[v] = &mesh;
          at[v] = static_cast<std::uint32_t>(mesh.vertices.size());
          mesh.vertices.push_back(placed[v]);
        }
        mesh.indices.push_back(at[v]);
      }
      MeshFace f;
      f.first_ring = static_cast<std::uint32_t>(mesh.ring_count());
      f.ring_count = 1;
      f.kind = SurfaceKind::Unknown;
      f.lod = 255;
      mesh.ring_offsets.push_back(static_cast<std::uint32_t>(mesh.indices.size()));
      mesh.faces.push_back(f);
      ++info_.faces;
    };
    if (pr.mode == kTriangles) {
      for (std::size_t k = 0; k + 3 <= idx.size(); k += 3) tri(idx[k], idx[k + 1], idx[k + 2]);
    } else {
      for (std::size_t k = 2; k < idx.size(); ++k) {
        if (pr.mode == kTriangleFan) tri(idx[0], idx[k - 1], idx[k]);
        else if (k % 2 == 0) tri(idx[k - 2], idx[k - 1], idx[k]);
        else tri(idx[k - 1], idx[k - 2], idx[k]);
      }
    }
    ++info_.primitives;
    return true;
  }

  const std::string& path_;
  const GltfOptions& opt_;
  const GltfTile* tile_;
  const GltfMeshCallback& cb_;
  std::vector<Problem>& problems_;
  GltfInfo& info_;
  const tinygltf::Model& m_;
  std::vector<bool> on_stack_;
  Point3 rtc_;
  bool has_rtc_ = false, stopped_ = false;
  bool instancing_ = false;   // an EXT_mesh_gpu_instancing instance is being read
  bool by_instance_ = false;  // some node was instanced: its buildings are its instances
  std::size_t total_vertices_ = 0;
  std::unordered_map<std::string, Mesh> features_;  // building by "table:feature id"
  std::vector<std::string> feature_order_;          // in the order first met
  mutable std::map<int, std::vector<unsigned char>> view_cache_;
  mutable std::set<int> checked_views_;
};

/// A GLB whose JSON chunk gltf::loadable_json changes, rebuilt with the new chunk; empty when nothing
/// changes or the GLB's chunks are malformed (tinygltf then says what is wrong).
std::string loadable_glb(const std::string& glb) {
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, glb.data() + at, 4);
    return v;
  };
  if (glb.size() < 20 || u32(12) > glb.size() - 20 || u32(16) != 0x4E4F534Au) return {};  // "JSON"
  const std::size_t json_length = u32(12);
  const std::string json = gltf::loadable_json(std::string_view(glb).substr(20, json_length));
  if (json.empty()) return {};
  std::string out = "glTF";
  auto put = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  std::string padded = json;
  while (padded.size() % 4) padded += ' ';
  const std::string rest = glb.substr(20 + json_length);  // the BIN chunk, if any, as it was
  put(2);
  put(static_cast<std::uint32_t>(12 + 8 + padded.size() + rest.size()));
  put(static_cast<std::uint32_t>(padded.size()));
  put(0x4E4F534Au);
  out += padded;
  out += rest;
  return out;
}

}  // namespace

void read_gltf(const std::string& path, const GltfOptions& options, const GltfMeshCallback& on_mesh,
               std::vector<Problem>& problems, GltfInfo& info) {
  xml::ByteBudget budget;
  budget.max_entry_bytes = options.max_bytes;
  budget.max_total_bytes = options.max_bytes;
  const std::string bytes = xml::read_vsi_file(path, path, budget);
  read_gltf_bytes(path, bytes, fs::path(path).parent_path().string(), options, nullptr, on_mesh, problems, info);
}

void read_gltf_bytes(const std::string& path, const std::string& bytes_in, const std::string& root_folder,
                     const GltfOptions& options, const GltfTile* tile, const GltfMeshCallback& on_mesh,
                     std::vector<Problem>& problems, GltfInfo& info) {
  if (tile) return read_gltf_instances(path, bytes_in, root_folder, options, {*tile}, on_mesh, problems, info);
  read_gltf_instances(path, bytes_in, root_folder, options, {}, on_mesh, problems, info);
}

void read_gltf_instances(const std::string& path, const std::string& bytes_in, const std::string& root_folder,
                         const GltfOptions& options, const std::vector<GltfTile>& tiles, const GltfMeshCallback& on_mesh,
                         std::vector<Problem>& problems, GltfInfo& info) {
  const bool tiled = !tiles.empty();
  info = GltfInfo{};
  info.file = path;
  xml::ByteBudget budget;  // the external buffers
  budget.max_entry_bytes = options.max_bytes;
  budget.max_total_bytes = options.max_bytes;
  if (bytes_in.size() > std::numeric_limits<unsigned int>::max())
    throw InputError(path + ": larger than 4 GiB, which tinygltf cannot take");

  FsGuard guard;
  guard.budget = &budget;
  guard.vsi = path.rfind("/vsi", 0) == 0;
  const fs::path folder = root_folder;
  std::error_code ec;
  guard.root = guard.vsi ? folder : fs::weakly_canonical(folder.empty() ? fs::path(".") : folder, ec);
  if (ec) throw InputError(path + ": cannot resolve the file's folder: " + ec.message());
  const std::string base_dir = guard.vsi || !tiled ? guard.root.string()
                                                  : fs::weakly_canonical(fs::path(path).parent_path(), ec).string();

  const bool glb = bytes_in.size() >= 4 && std::memcmp(bytes_in.data(), "glTF", 4) == 0;
  // Compressed files: made loadable for tinygltf first (gltf_extensions.h), decoded after.
  std::string rewritten;
  try {
    rewritten = glb ? loadable_glb(bytes_in) : gltf::loadable_json(bytes_in);
  } catch (const std::exception& e) {
    throw InputError(path + ": not a readable glTF 2.0 " + (glb ? "binary (GLB)" : "file") + ": " + e.what());
  }
  const std::string& bytes = rewritten.empty() ? bytes_in : rewritten;

  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&fs_exists, &fs_expand, &fs_read, &fs_write, &guard});
  loader.SetImageLoader(&no_image, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool ok =
      glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                        static_cast<unsigned int>(bytes.size()), base_dir)
          : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()),
                                       base_dir);
  if (!ok) {
    while (!err.empty() && err.back() == '\n') err.pop_back();
    std::string msg = path + ": not a readable glTF 2.0 " + (glb ? "binary (GLB)" : "file") + ": " + err;
    if (!guard.refused.empty()) msg += " (a buffer uri points outside the glTF's folder: " + guard.refused + ")";
    throw InputError(msg);
  }
  const std::vector<std::string> unknown = gltf::unknown_required_extensions(model);
  if (!unknown.empty()) {
    std::string list;
    for (const std::string& e : unknown) list += (list.empty() ? "" : ", ") + e;
    throw InputError(path + ": requires the glTF extension" + (unknown.size() > 1 ? "s " : " ") + list +
                     ", which groundplan does not read (its geometry would come out wrong); supported: "
                     "KHR_draco_mesh_compression, EXT_meshopt_compression, KHR_meshopt_compression, "
                     "KHR_mesh_quantization, CESIUM_RTC, EXT_mesh_features, EXT_structural_metadata, EXT_mesh_gpu_instancing, "
                     "EXT_instance_features, and the "
                     "material and texture extensions (ignored)");
  }
  std::vector<std::string> decode_problems;
  gltf::decode(model, decode_problems);
  for (const std::string& why : decode_problems) problems.push_back(Problem{"", path, "read", "BAD_PRIMITIVE", why});
  if (!tiled) return Reader(path, options, nullptr, on_mesh, problems, info, model).run();
  // The model parsed and decoded once, placed once per tile (a 3D Tiles content; an i3dm's instances).
  GltfInfo total = info;
  for (const GltfTile& tile : tiles) {
    GltfInfo one = info;
    Reader(path, options, &tile, on_mesh, problems, one, model).run();
    total.nodes += one.nodes, total.meshes += one.meshes, total.primitives += one.primitives, total.faces += one.faces;
    total.by_feature = total.by_feature || one.by_feature;
    if (!one.georeference.empty()) total.georeference = one.georeference;
    if (total.faces * 3 > options.max_vertices && &tile != &tiles.back()) {  // the bound over all instances
      problems.push_back(Problem{"", path, "read", "TOO_LARGE",
                                 "its instances hold more than " + std::to_string(options.max_vertices) +
                                     " vertices together: the instances after " + std::to_string(&tile - tiles.data() + 1) +
                                     " of " + std::to_string(tiles.size()) + " are not read"});
      break;
    }
  }
  info = total;
}

}  // namespace groundplan::gis

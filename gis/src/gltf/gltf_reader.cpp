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

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;
using detail::Mat4;

constexpr int kTriangles = 4, kTriangleStrip = 5, kTriangleFan = 6;
constexpr int kFloat = 5126, kUByte = 5121, kUShort = 5123, kUInt = 5125;
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

class Reader {
 public:
  Reader(const std::string& path, const GltfOptions& opt, const GltfMeshCallback& cb, std::vector<Problem>& problems,
         GltfInfo& info, tinygltf::Model& model)
      : path_(path), opt_(opt), cb_(cb), problems_(problems), info_(info), m_(model) {}

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
    // glTF is y-up; 3D Tiles and we are z-up: (x, y, z) -> (x, -z, y).
    const Mat4 y_up_to_z_up = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1};
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
    for (int r : roots) visit(r, y_up_to_z_up, 0);
    if (info_.meshes == 0) problem("", "NO_GEOMETRY", "the glTF scene holds no triangle geometry");
  }

 private:
  void problem(const std::string& id, const std::string& code, const std::string& reason) {
    problems_.push_back(Problem{id, path_, "read", code, reason});
  }

  void visit(int index, const Mat4& parent, int depth) {
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
    if (n.mesh >= 0) emit(n, index, world);
    for (int c : n.children) visit(c, world, depth + 1);
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
      return why = "bufferView's buffer is out of range", false;
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

  void emit(const tinygltf::Node& n, int index, const Mat4& world) {
    const std::string id = n.name.empty() ? "node " + std::to_string(index) : n.name;
    if (static_cast<std::size_t>(n.mesh) >= m_.meshes.size()) {
      problem(id, "BAD_REFERENCE", "the node's mesh index " + std::to_string(n.mesh) + " is out of range");
      return;
    }
    if (!finite(world)) {
      problem(id, "BAD_TRANSFORM", "the node's transform holds NaN or infinity");
      return;
    }
    Mesh mesh;
    mesh.source_id = id;
    mesh.name = m_.meshes[static_cast<std::size_t>(n.mesh)].name;
    mesh.source_file = path_;
    for (const tinygltf::Primitive& pr : m_.meshes[static_cast<std::size_t>(n.mesh)].primitives) {
      std::string why;
      if (!primitive(pr, world, mesh, why)) problem(id, "BAD_PRIMITIVE", "a primitive is skipped: " + why);
      if (stopped_) break;
    }
    if (mesh.faces.empty()) return;
    // The frame: ECEF when CESIUM_RTC says so or the positions sit at the Earth's radius.
    GltfFrame frame = GltfFrame::Local;
    if (has_rtc_) {
      for (Point3& p : mesh.vertices) p.x += rtc_.x, p.y += rtc_.y, p.z += rtc_.z;
      frame = GltfFrame::Ecef;
    } else {
      const Point3& p = mesh.vertices.front();
      const double r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
      if (r > kEarthMin && r < kEarthMax) {
        frame = GltfFrame::Ecef;
        if (info_.georeference.empty()) info_.georeference = "ECEF node transform";
      }
    }
    ++info_.meshes;
    cb_(std::move(mesh), frame);
  }

  bool primitive(const tinygltf::Primitive& pr, const Mat4& world, Mesh& mesh, std::string& why) {
    if (pr.mode != kTriangles && pr.mode != kTriangleStrip && pr.mode != kTriangleFan) return true;  // points, lines
    if (pr.extensions.count("KHR_draco_mesh_compression"))
      return why = "KHR_draco_mesh_compression is not supported", false;
    auto pos = pr.attributes.find("POSITION");
    if (pos == pr.attributes.end()) return why = "no POSITION attribute", false;
    if (pos->second < 0 || static_cast<std::size_t>(pos->second) >= m_.accessors.size())
      return why = "POSITION accessor index is out of range", false;
    const tinygltf::Accessor& pa = m_.accessors[static_cast<std::size_t>(pos->second)];
    if (pa.type != TINYGLTF_TYPE_VEC3 || pa.componentType != kFloat)
      return why = "POSITION is not VEC3 of FLOAT (quantized positions are not supported)", false;
    const unsigned char* pbase = nullptr;
    std::size_t pstride = 0;
    if (!view(pa, 12, pbase, pstride, why)) return why = "POSITION: " + why, false;
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
        const unsigned char* e = ibase + k * istride;
        std::uint32_t v = 0;
        if (size == 1) v = *e;
        else if (size == 2) { std::uint16_t s; std::memcpy(&s, e, 2); v = s; }
        else std::memcpy(&v, e, 4);
        if (v >= pa.count) return why = "index " + std::to_string(v) + " is out of range (" + std::to_string(pa.count) + " positions)", false;
        idx[k] = v;
      }
    } else {
      idx.resize(pa.count);
      for (std::size_t k = 0; k < pa.count; ++k) idx[k] = static_cast<std::uint32_t>(k);
    }
    const std::uint32_t base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (std::size_t k = 0; k < pa.count; ++k) {
      float f[3];
      std::memcpy(f, pbase + k * pstride, 12);
      if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) {
        mesh.vertices.resize(base);
        return why = "a position is NaN or infinite", false;
      }
      mesh.vertices.push_back(detail::apply(world, Point3{f[0], f[1], f[2]}));
    }
    total_vertices_ += pa.count;
    auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      MeshFace f;
      f.first_ring = static_cast<std::uint32_t>(mesh.ring_count());
      f.ring_count = 1;
      f.kind = SurfaceKind::Unknown;
      f.lod = 255;
      mesh.indices.insert(mesh.indices.end(), {base + a, base + b, base + c});
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
  const GltfMeshCallback& cb_;
  std::vector<Problem>& problems_;
  GltfInfo& info_;
  const tinygltf::Model& m_;
  std::vector<bool> on_stack_;
  Point3 rtc_;
  bool has_rtc_ = false, stopped_ = false;
  std::size_t total_vertices_ = 0;
};

}  // namespace

void read_gltf(const std::string& path, const GltfOptions& options, const GltfMeshCallback& on_mesh,
               std::vector<Problem>& problems, GltfInfo& info) {
  info = GltfInfo{};
  info.file = path;
  xml::ByteBudget budget;
  budget.max_entry_bytes = options.max_bytes;
  budget.max_total_bytes = options.max_bytes;
  const std::string bytes = xml::read_vsi_file(path, path, budget);
  if (bytes.size() > std::numeric_limits<unsigned int>::max())
    throw InputError(path + ": larger than 4 GiB, which tinygltf cannot take");

  FsGuard guard;
  guard.budget = &budget;
  guard.vsi = path.rfind("/vsi", 0) == 0;
  const fs::path folder = fs::path(path).parent_path();
  std::error_code ec;
  guard.root = guard.vsi ? folder : fs::weakly_canonical(folder.empty() ? fs::path(".") : folder, ec);
  if (ec) throw InputError(path + ": cannot resolve the file's folder: " + ec.message());

  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(tinygltf::FsCallbacks{&fs_exists, &fs_expand, &fs_read, &fs_write, &guard});
  loader.SetImageLoader(&no_image, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  const std::string base_dir = guard.root.string();
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
  Reader(path, options, on_mesh, problems, info, model).run();
}

}  // namespace groundplan::gis

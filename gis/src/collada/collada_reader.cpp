// SPDX-License-Identifier: MIT
// COLLADA reader (issue 6). One expat pass collects geometries (sources, vertices, primitives),
// nodes (transforms in document order, instances, children) and visual scenes into compact tables;
// the scene is then walked from the root with a bounded depth and instance count, and every
// instance_geometry appends its transformed vertices once and its faces as index rings.
//
// Why not DOM: a .dae from a KMZ is usually small, but SketchUp / FBX exports of whole districts
// reach hundreds of MB of float text; the tables keep numbers (8 bytes each), not text and nodes.
#include <groundplan/error.h>
#include <groundplan/gis/collada.h>

#include "citygml/coordinates.h"
#include "collada/collada_internal.h"
#include "xml/safe_xml.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace groundplan::gis {
namespace detail {

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[i * 4 + k] * b[k * 4 + j];
      r[i * 4 + j] = s;
    }
  return r;
}

Point3 apply(const Mat4& m, const Point3& p) {
  return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
          m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}

Mat4 rotation(double x, double y, double z, double angle_deg) {
  const double len = std::sqrt(x * x + y * y + z * z);
  if (!(len > 0) || !std::isfinite(len)) return kIdentity;
  x /= len, y /= len, z /= len;
  const double a = angle_deg * std::numbers::pi / 180.0;
  const double c = std::cos(a), s = std::sin(a), t = 1 - c;
  return {t * x * x + c,     t * x * y - s * z, t * x * z + s * y, 0,  //
          t * x * y + s * z, t * y * y + c,     t * y * z - s * x, 0,  //
          t * x * z - s * y, t * y * z + s * x, t * z * z + c,     0,  //
          0,                 0,                 0,                 1};
}

Mat4 translation(double x, double y, double z) { return {1, 0, 0, x, 0, 1, 0, y, 0, 0, 1, z, 0, 0, 0, 1}; }
Mat4 scaling(double x, double y, double z) { return {x, 0, 0, 0, 0, y, 0, 0, 0, 0, z, 0, 0, 0, 0, 1}; }

}  // namespace detail

namespace {

using detail::Mat4;

enum class PrimType : std::uint8_t { Triangles, Polylist, Polygons, Trifans, Tristrips };

struct Source {
  std::vector<double> floats;
  std::size_t count = 0, stride = 1, offset = 0;
  bool has_accessor = false;
};

struct Input {
  std::string semantic, source;
  std::size_t offset = 0;
};

struct IndexRange {
  std::size_t begin = 0, end = 0;
};

struct Polygon {  // one <p> of polygons/trifans/tristrips, or a <ph>'s <p> and <h>s
  IndexRange outer;
  std::vector<IndexRange> holes;
};

struct Primitive {
  PrimType type = PrimType::Triangles;
  std::size_t declared_count = 0;
  std::vector<Input> inputs;
  std::vector<std::uint32_t> idx;     // every <p>/<h> value, concatenated
  std::vector<Polygon> lists;         // polygons/trifans/tristrips (and polylist/triangles: one entry)
  std::vector<std::uint32_t> vcount;  // polylist
  std::string defect;                 // set when numbers were bad: the primitive is skipped
  std::size_t line = 0;
};

struct Geometry {
  std::string id, name;
  std::unordered_map<std::string, Source> sources;
  std::unordered_map<std::string, std::string> vertices;  // <vertices id> -> POSITION source id
  std::vector<Primitive> prims;
};

enum class TransformKind : std::uint8_t { Matrix, Translate, Rotate, Scale, Lookat, Skew };

struct Node {
  std::string id, name;
  Mat4 local = detail::kIdentity;
  std::vector<std::string> geometry_urls;
  std::vector<std::string> node_urls;
  std::vector<int> children;
};

// Element roles on the parse stack.
enum class El : std::uint8_t {
  Other, Root, Asset, Unit, UpAxis, LibGeometries, Geometry, Mesh, Source, FloatArray, TechniqueCommon, Accessor,
  Vertices, Primitive, P, Ph, H, VCount, LibNodes, VisualScene, Node, Transform, InstanceGeometry, InstanceNode,
  Scene, LibVisualScenes, Skip,
};

std::string strip_hash(const char* url) {
  if (!url) return {};
  std::string_view s(url);
  if (!s.empty() && s[0] == '#') s.remove_prefix(1);
  return std::string(s);
}

bool is_local_url(const char* url) { return url && url[0] == '#'; }

constexpr std::size_t kMaxInputOffset = 1024;  // real files use < 10 inputs per primitive

class Parser final : public xml::Handler {
 public:
  Parser(const std::string& name, std::vector<Problem>& problems, ColladaInfo& info, const std::string& source_id)
      : name_(name), problems_(problems), info_(info), source_id_(source_id) {}

  void attach(xml::SafeParser* p) { xml_ = p; }

  void start(std::string_view uri, std::string_view local, const char** atts) override {
    const El parent = stack_.empty() ? El::Other : stack_.back();
    if (parent == El::Skip) {
      stack_.push_back(El::Skip);
      return;
    }
    El el = El::Other;
    if (stack_.empty()) {
      if (local != "COLLADA")
        throw InputError(name_ + ": the root element is <" + std::string(local) + ">, not <COLLADA>: not a COLLADA file");
      if (const char* v = xml::attribute(atts, "version")) info_.version = v;
      el = El::Root;
    } else {
      el = classify(parent, local, atts);
    }
    stack_.push_back(el);
  }

  void end(std::string_view, std::string_view local) override {
    const El el = stack_.back();
    stack_.pop_back();
    switch (el) {
      case El::UpAxis: {
        std::string v = trimmed();
        if (v == "X_UP" || v == "Y_UP" || v == "Z_UP") info_.up_axis = v;
        else if (!v.empty()) note("UNKNOWN_UP_AXIS", "up_axis \"" + v + "\" is not X_UP, Y_UP or Z_UP: Y_UP assumed");
        end_text();
        break;
      }
      case El::FloatArray: {
        Source& s = geometry().sources[source_id_cur_];
        std::vector<double> values;
        if (detail::parse_numbers(text_, values) != detail::CoordStatus::Ok)
          source_defect_ = "float_array of source \"" + source_id_cur_ + "\" holds a bad number";
        s.floats = std::move(values);
        end_text();
        break;
      }
      case El::P:
      case El::H: {
        Primitive& pr = geometry().prims.back();
        const std::size_t begin = pr.idx.size();
        parse_indices(pr);
        IndexRange r{begin, pr.idx.size()};
        if (stack_.back() == El::Ph) {
          if (el == El::P) {
            pr.lists.push_back(Polygon{r, {}});
          } else if (!pr.lists.empty()) {
            pr.lists.back().holes.push_back(r);
          }
        } else {
          pr.lists.push_back(Polygon{r, {}});
        }
        end_text();
        break;
      }
      case El::VCount: {
        Primitive& pr = geometry().prims.back();
        std::vector<double> values;
        if (detail::parse_numbers(text_, values) != detail::CoordStatus::Ok) pr.defect = "<vcount> holds a bad number";
        for (double v : values) {
          if (!(v >= 0 && v < 1e9 && v == std::floor(v))) {
            pr.defect = "<vcount> holds a value that is not a polygon size";
            break;
          }
          pr.vcount.push_back(static_cast<std::uint32_t>(v));
        }
        end_text();
        break;
      }
      case El::Transform: {
        apply_transform();
        end_text();
        break;
      }
      case El::Node:
        node_stack_.pop_back();
        break;
      case El::Source:
        if (!source_defect_.empty()) {
          geometry().sources.erase(source_id_cur_);
          problem("BAD_SOURCE", source_defect_ + ": the source is ignored");
          source_defect_.clear();
        }
        break;
      default:
        break;
    }
    (void)local;
  }

  void text(std::string_view chunk) override { text_.append(chunk); }

  // Results.
  std::vector<Geometry> geometries;
  std::unordered_map<std::string, std::size_t> geometry_by_id;
  std::vector<Node> nodes;
  std::unordered_map<std::string, int> node_by_id;
  std::unordered_map<std::string, std::vector<int>> scenes;  // visual_scene id -> root nodes
  std::string first_scene;
  std::string scene_url;
  bool saw_unsupported_transform = false;

  void problem(const std::string& code, const std::string& reason) {
    problems_.push_back(Problem{source_id_, name_, "read", code, reason});
  }
  void note(const std::string& code, const std::string& reason) { problem(code, reason); }

 private:
  El classify(El parent, std::string_view local, const char** atts) {
    switch (parent) {
      case El::Root:
        if (local == "asset") return El::Asset;
        if (local == "library_geometries") return El::LibGeometries;
        if (local == "library_nodes") return El::LibNodes;
        if (local == "library_visual_scenes") return El::LibVisualScenes;
        if (local == "scene") return El::Scene;
        return El::Skip;  // images, materials, effects, animations, controllers, cameras, lights, extra
      case El::Asset:
        if (local == "unit") {
          if (const char* m = xml::attribute(atts, "meter")) {
            char* end = nullptr;
            const double v = std::strtod(m, &end);
            if (end != m && std::isfinite(v) && v > 0) {
              info_.unit_m = v;
            } else {
              note("BAD_UNIT", std::string("<unit meter=\"") + m + "\"> is not a positive number: metres assumed");
            }
          }
          return El::Unit;
        }
        if (local == "up_axis") {
          begin_text();
          return El::UpAxis;
        }
        return El::Skip;
      case El::LibGeometries:
        if (local == "geometry") {
          Geometry g;
          g.id = strip_hash(xml::attribute(atts, "id"));
          if (const char* n = xml::attribute(atts, "name")) g.name = n;
          geometries.push_back(std::move(g));
          if (!geometries.back().id.empty()) geometry_by_id[geometries.back().id] = geometries.size() - 1;
          return El::Geometry;
        }
        return El::Skip;
      case El::Geometry:
        if (local == "mesh") {
          ++info_.geometries;
          return El::Mesh;
        }
        return El::Skip;  // convex_mesh, spline, brep: no polygons to read
      case El::Mesh:
        if (local == "source") {
          source_id_cur_ = strip_hash(xml::attribute(atts, "id"));
          geometry().sources[source_id_cur_];
          source_defect_.clear();
          return El::Source;
        }
        if (local == "vertices") {
          vertices_id_ = strip_hash(xml::attribute(atts, "id"));
          return El::Vertices;
        }
        if (local == "triangles" || local == "polylist" || local == "polygons" || local == "trifans" ||
            local == "tristrips") {
          Primitive pr;
          pr.type = local == "triangles"  ? PrimType::Triangles
                    : local == "polylist" ? PrimType::Polylist
                    : local == "polygons" ? PrimType::Polygons
                    : local == "trifans"  ? PrimType::Trifans
                                          : PrimType::Tristrips;
          if (const char* c = xml::attribute(atts, "count")) pr.declared_count = std::strtoull(c, nullptr, 10);
          pr.line = xml_ ? xml_->line() : 0;
          geometry().prims.push_back(std::move(pr));
          return El::Primitive;
        }
        return El::Skip;  // lines, linestrips: no area
      case El::Source:
        if (local == "float_array") {
          begin_text();
          return El::FloatArray;
        }
        if (local == "technique_common") return El::TechniqueCommon;
        return El::Skip;
      case El::TechniqueCommon:
        if (local == "accessor") {
          Source& s = geometry().sources[source_id_cur_];
          s.has_accessor = true;
          if (const char* c = xml::attribute(atts, "count")) s.count = std::strtoull(c, nullptr, 10);
          if (const char* c = xml::attribute(atts, "stride")) s.stride = std::strtoull(c, nullptr, 10);
          if (const char* c = xml::attribute(atts, "offset")) s.offset = std::strtoull(c, nullptr, 10);
          return El::Accessor;
        }
        return El::Skip;
      case El::Vertices:
        if (local == "input") {
          const char* sem = xml::attribute(atts, "semantic");
          if (sem && std::strcmp(sem, "POSITION") == 0)
            geometry().vertices[vertices_id_] = strip_hash(xml::attribute(atts, "source"));
        }
        return El::Skip;
      case El::Primitive: {
        Primitive& pr = geometry().prims.back();
        if (local == "input") {
          Input in;
          if (const char* v = xml::attribute(atts, "semantic")) in.semantic = v;
          in.source = strip_hash(xml::attribute(atts, "source"));
          if (const char* v = xml::attribute(atts, "offset")) in.offset = std::strtoull(v, nullptr, 10);
          if (in.offset > kMaxInputOffset) pr.defect = "an <input> offset is implausibly large";
          pr.inputs.push_back(std::move(in));
          return El::Skip;
        }
        if (local == "p") {
          begin_text();
          return El::P;
        }
        if (local == "vcount") {
          begin_text();
          return El::VCount;
        }
        if (local == "ph") return El::Ph;
        return El::Skip;
      }
      case El::Ph:
        if (local == "p") {
          begin_text();
          return El::P;
        }
        if (local == "h") {
          begin_text();
          return El::H;
        }
        return El::Skip;
      case El::LibNodes:
        if (local == "node") return open_node(atts, -1);
        return El::Skip;
      case El::LibVisualScenes:
        if (local == "visual_scene") {
          scene_cur_ = strip_hash(xml::attribute(atts, "id"));
          if (first_scene.empty()) first_scene = scene_cur_;
          scenes[scene_cur_];
          return El::VisualScene;
        }
        return El::Skip;
      case El::VisualScene:
        if (local == "node") {
          const El e = open_node(atts, -1);
          scenes[scene_cur_].push_back(node_stack_.back());
          return e;
        }
        return El::Skip;
      case El::Node:
        if (local == "node") {
          const int parent_index = node_stack_.back();
          const El e = open_node(atts, parent_index);
          nodes[static_cast<std::size_t>(parent_index)].children.push_back(node_stack_.back());
          return e;
        }
        if (local == "matrix" || local == "translate" || local == "rotate" || local == "scale" || local == "lookat" ||
            local == "skew") {
          transform_kind_ = local == "matrix"      ? TransformKind::Matrix
                            : local == "translate" ? TransformKind::Translate
                            : local == "rotate"    ? TransformKind::Rotate
                            : local == "scale"     ? TransformKind::Scale
                            : local == "lookat"    ? TransformKind::Lookat
                                                   : TransformKind::Skew;
          begin_text();
          return El::Transform;
        }
        if (local == "instance_geometry") {
          const char* url = xml::attribute(atts, "url");
          if (is_local_url(url)) {
            current_node().geometry_urls.push_back(strip_hash(url));
          } else {
            problem("EXTERNAL_REFERENCE", std::string("instance_geometry url=\"") + (url ? url : "") +
                                              "\" points outside the document: not followed");
          }
          return El::Skip;
        }
        if (local == "instance_node") {
          const char* url = xml::attribute(atts, "url");
          if (is_local_url(url)) {
            current_node().node_urls.push_back(strip_hash(url));
          } else {
            problem("EXTERNAL_REFERENCE", std::string("instance_node url=\"") + (url ? url : "") +
                                              "\" points outside the document: not followed");
          }
          return El::Skip;
        }
        if (local == "instance_controller")
          problem("UNSUPPORTED_GEOMETRY", "instance_controller (skinned or morphed geometry) is not read");
        return El::Skip;
      case El::Scene:
        if (local == "instance_visual_scene") scene_url = strip_hash(xml::attribute(atts, "url"));
        return El::Skip;
      default:
        return El::Skip;
    }
  }

  El open_node(const char** atts, int parent) {
    Node n;
    if (const char* v = xml::attribute(atts, "id")) n.id = v;
    if (const char* v = xml::attribute(atts, "name")) n.name = v;
    nodes.push_back(std::move(n));
    const int index = static_cast<int>(nodes.size() - 1);
    if (!nodes.back().id.empty()) node_by_id.emplace(nodes.back().id, index);
    node_stack_.push_back(index);
    (void)parent;
    return El::Node;
  }

  Node& current_node() { return nodes[static_cast<std::size_t>(node_stack_.back())]; }
  Geometry& geometry() { return geometries.back(); }

  void begin_text() {
    text_.clear();
    if (xml_) xml_->capture_text(true);
  }
  void end_text() {
    text_.clear();
    if (xml_) xml_->capture_text(false);
  }
  std::string trimmed() const {
    const auto b = text_.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return {};
    const auto e = text_.find_last_not_of(" \t\r\n");
    return text_.substr(b, e - b + 1);
  }

  void parse_indices(Primitive& pr) {
    scratch_.clear();
    if (detail::parse_numbers(text_, scratch_) != detail::CoordStatus::Ok) {
      pr.defect = "a <p> holds something that is not a number";
      return;
    }
    for (double v : scratch_) {
      if (!(v >= 0 && v < 4294967295.0 && v == std::floor(v))) {
        pr.defect = "a <p> holds an index that is negative, fractional or too large";
        return;
      }
      pr.idx.push_back(static_cast<std::uint32_t>(v));
    }
  }

  void apply_transform() {
    scratch_.clear();
    const bool ok = detail::parse_numbers(text_, scratch_) == detail::CoordStatus::Ok;
    const std::vector<double>& v = scratch_;
    Mat4 m = detail::kIdentity;
    auto bad = [&](const char* what) {
      problem("BAD_TRANSFORM", std::string("a node's <") + what + "> does not hold the numbers it needs: ignored");
    };
    switch (transform_kind_) {
      case TransformKind::Matrix:
        if (!ok || v.size() != 16) return bad("matrix");
        std::copy(v.begin(), v.end(), m.begin());
        break;
      case TransformKind::Translate:
        if (!ok || v.size() != 3) return bad("translate");
        m = detail::translation(v[0], v[1], v[2]);
        break;
      case TransformKind::Rotate:
        if (!ok || v.size() != 4) return bad("rotate");
        m = detail::rotation(v[0], v[1], v[2], v[3]);
        break;
      case TransformKind::Scale:
        if (!ok || v.size() != 3) return bad("scale");
        m = detail::scaling(v[0], v[1], v[2]);
        break;
      case TransformKind::Lookat:
      case TransformKind::Skew:
        saw_unsupported_transform = true;
        return;
    }
    Node& n = current_node();
    n.local = detail::multiply(n.local, m);  // document order: post-multiply
  }

  std::string name_;
  std::vector<Problem>& problems_;
  ColladaInfo& info_;
  std::string source_id_;
  xml::SafeParser* xml_ = nullptr;
  std::vector<El> stack_;
  std::vector<int> node_stack_;
  std::string text_;
  std::vector<double> scratch_;
  std::string source_id_cur_, source_defect_, vertices_id_, scene_cur_;
  TransformKind transform_kind_ = TransformKind::Matrix;
};

/// Walks the scene and fills the mesh.
class Builder {
 public:
  Builder(Parser& p, const ColladaOptions& opt, ColladaInfo& info, Mesh& mesh)
      : p_(p), opt_(opt), info_(info), mesh_(mesh) {}

  void build() {
    // Unit and up axis first: every position becomes up_conversion · unit · world · p.
    Mat4 root = detail::scaling(info_.unit_m, info_.unit_m, info_.unit_m);
    if (info_.up_axis == "Y_UP") {
      // right +x, up +y, in +z  ->  x east, y north, z up: (x, y, z) -> (x, -z, y)
      root = detail::multiply(Mat4{1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1}, root);
    } else if (info_.up_axis == "X_UP") {
      // right -y, up +x, in +z  ->  (x, y, z) -> (-y, -z, x)
      root = detail::multiply(Mat4{0, -1, 0, 0, 0, 0, -1, 0, 1, 0, 0, 0, 0, 0, 0, 1}, root);
    }
    std::string scene = p_.scene_url;
    if (!scene.empty() && !p_.scenes.count(scene)) {
      p_.problem("LINK_TARGET_NOT_FOUND", "scene/instance_visual_scene url=\"#" + scene +
                                              "\" names no visual_scene: the first one is used");
      scene.clear();
    }
    if (scene.empty()) scene = p_.first_scene;
    if (!scene.empty()) {
      for (int root_node : p_.scenes[scene]) visit(root_node, root, 0);
    } else if (!p_.geometries.empty()) {
      // No scene at all: every geometry once, untransformed (a bare geometry library).
      p_.problem("NO_SCENE", "no visual_scene: every geometry is taken once, without node transforms");
      for (std::size_t g = 0; g < p_.geometries.size(); ++g) emit(g, root);
    }
    if (p_.saw_unsupported_transform)
      p_.problem("UNSUPPORTED_TRANSFORM", "<lookat> and <skew> node transforms are not applied");
  }

 private:
  void visit(int index, const Mat4& parent, int depth) {
    if (stopped_) return;
    if (depth > opt_.max_instance_depth) {
      if (!depth_reported_)
        p_.problem("INSTANCE_DEPTH", "node hierarchy / instance_node chain deeper than " +
                                         std::to_string(opt_.max_instance_depth) +
                                         " levels (a cycle?): the deeper part is not read");
      depth_reported_ = true;
      return;
    }
    if (++visits_ > kMaxVisits) {
      p_.problem("TOO_MANY_INSTANCES", "the scene expands to more than " + std::to_string(kMaxVisits) +
                                           " node instances: the rest is not read");
      stopped_ = true;
      return;
    }
    const Node& n = p_.nodes[static_cast<std::size_t>(index)];
    const Mat4 world = detail::multiply(parent, n.local);
    for (const std::string& url : n.geometry_urls) {
      auto it = p_.geometry_by_id.find(url);
      if (it == p_.geometry_by_id.end()) {
        p_.problem("LINK_TARGET_NOT_FOUND", "instance_geometry url=\"#" + url + "\" names no geometry");
        continue;
      }
      emit(it->second, world);
    }
    for (const std::string& url : n.node_urls) {
      auto it = p_.node_by_id.find(url);
      if (it == p_.node_by_id.end()) {
        p_.problem("LINK_TARGET_NOT_FOUND", "instance_node url=\"#" + url + "\" names no node");
        continue;
      }
      ++info_.node_instances;
      visit(it->second, world, depth + 1);
    }
    for (int child : n.children) visit(child, world, depth + 1);
  }

  /// Positions of `src` transformed by `m`, appended once per (instance, source); returns their base.
  bool append_positions(const Source& src, const Mat4& m, std::uint32_t& base, std::size_t& count) {
    count = src.has_accessor ? src.count : src.floats.size() / 3;
    const std::size_t stride = src.has_accessor ? src.stride : 3;
    const std::size_t offset = src.has_accessor ? src.offset : 0;
    if (stride < 3) return false;
    if (count > 0 && (offset + (count - 1) * stride + 3 > src.floats.size())) return false;
    if (mesh_.vertices.size() + count > opt_.max_vertices) {
      p_.problem("TOO_MANY_VERTICES", "the scene expands to more than " + std::to_string(opt_.max_vertices) +
                                          " vertices: the rest is not read");
      stopped_ = true;
      return false;
    }
    base = static_cast<std::uint32_t>(mesh_.vertices.size());
    for (std::size_t i = 0; i < count; ++i) {
      const double* f = &src.floats[offset + i * stride];
      mesh_.vertices.push_back(detail::apply(m, Point3{f[0], f[1], f[2]}));
    }
    return true;
  }

  void emit(std::size_t gi, const Mat4& m) {
    if (stopped_) return;
    const Geometry& g = p_.geometries[gi];
    ++info_.geometry_instances;
    std::unordered_map<std::string, std::pair<std::uint32_t, std::size_t>> placed;  // source -> base, count
    for (const Primitive& pr : g.prims) {
      if (stopped_) return;
      const std::string where = "geometry \"" + g.id + "\" primitive at line " + std::to_string(pr.line);
      if (!pr.defect.empty()) {
        p_.problem("BAD_INDICES", where + ": " + pr.defect + "; the primitive is skipped");
        continue;
      }
      // The VERTEX input (or, off-standard, a direct POSITION input) and the index stride.
      const Input* vin = nullptr;
      std::size_t stride = 1;
      for (const Input& in : pr.inputs) {
        stride = std::max(stride, in.offset + 1);
        if (in.semantic == "VERTEX" || (!vin && in.semantic == "POSITION")) vin = &in;
      }
      if (!vin) {
        p_.problem("NO_POSITIONS", where + ": no VERTEX input; the primitive is skipped");
        continue;
      }
      std::string source_id = vin->source;
      if (vin->semantic == "VERTEX") {
        auto v = g.vertices.find(vin->source);
        if (v == g.vertices.end()) {
          p_.problem("NO_POSITIONS", where + ": VERTEX input \"#" + vin->source + "\" names no <vertices> with POSITION");
          continue;
        }
        source_id = v->second;
      }
      auto s = g.sources.find(source_id);
      if (s == g.sources.end()) {
        p_.problem("NO_POSITIONS", where + ": position source \"#" + source_id + "\" is missing or unusable");
        continue;
      }
      auto pl = placed.find(source_id);
      if (pl == placed.end()) {
        std::uint32_t base = 0;
        std::size_t count = 0;
        if (!append_positions(s->second, m, base, count)) {
          if (!stopped_)
            p_.problem("BAD_SOURCE", where + ": position source \"#" + source_id +
                                         "\" has an accessor (count, stride, offset) that does not fit its float_array");
          continue;
        }
        pl = placed.emplace(source_id, std::make_pair(base, count)).first;
      }
      faces(pr, where, vin->offset, stride, pl->second.first, pl->second.second);
    }
  }

  /// Index of the k-th vertex tuple in range r, or false when out of bounds.
  bool vertex_at(const Primitive& pr, const IndexRange& r, std::size_t k, std::size_t voff, std::size_t stride,
                 std::size_t count, std::uint32_t base, std::uint32_t& out) const {
    const std::size_t at = r.begin + k * stride + voff;
    if (at >= r.end) return false;
    const std::uint32_t v = pr.idx[at];
    if (v >= count) return false;
    out = base + v;
    return true;
  }

  void faces(const Primitive& pr, const std::string& where, std::size_t voff, std::size_t stride, std::uint32_t base,
             std::size_t count) {
    std::size_t bad = 0;
    std::vector<std::uint32_t> ring;
    std::vector<std::vector<std::uint32_t>> holes;
    auto ring_of = [&](const IndexRange& r, std::size_t first, std::size_t n, std::vector<std::uint32_t>& out) {
      out.clear();
      for (std::size_t k = 0; k < n; ++k) {
        std::uint32_t v;
        if (!vertex_at(pr, r, first + k, voff, stride, count, base, v)) return false;
        out.push_back(v);
      }
      return true;
    };
    auto tuples = [&](const IndexRange& r) { return (r.end - r.begin) / stride; };

    switch (pr.type) {
      case PrimType::Triangles: {
        for (const Polygon& poly : pr.lists) {
          const std::size_t n = tuples(poly.outer);
          if ((poly.outer.end - poly.outer.begin) % stride != 0 || n % 3 != 0) ++bad;
          for (std::size_t t = 0; t + 3 <= n; t += 3) {
            if (ring_of(poly.outer, t, 3, ring)) add(ring, {});
            else ++bad;
          }
        }
        break;
      }
      case PrimType::Polylist: {
        std::size_t at = 0;
        const IndexRange all{0, pr.idx.size()};
        for (std::uint32_t vc : pr.vcount) {
          if (vc < 3 || at + vc > tuples(all)) {
            ++bad;
            at += vc;
            if (at > tuples(all)) break;
            continue;
          }
          if (ring_of(all, at, vc, ring)) add(ring, {});
          else ++bad;
          at += vc;
        }
        if (pr.vcount.empty() && !pr.idx.empty()) ++bad;
        break;
      }
      case PrimType::Polygons: {
        for (const Polygon& poly : pr.lists) {
          const std::size_t n = tuples(poly.outer);
          if (n < 3 || !ring_of(poly.outer, 0, n, ring)) {
            ++bad;
            continue;
          }
          holes.clear();
          bool ok = true;
          for (const IndexRange& h : poly.holes) {
            std::vector<std::uint32_t> hr;
            const std::size_t hn = tuples(h);
            if (hn < 3 || !ring_of(h, 0, hn, hr)) {
              ok = false;
              break;
            }
            holes.push_back(std::move(hr));
          }
          if (ok) add(ring, holes);
          else ++bad;
        }
        break;
      }
      case PrimType::Trifans:
      case PrimType::Tristrips: {
        std::vector<std::uint32_t> all;
        for (const Polygon& poly : pr.lists) {
          const std::size_t n = tuples(poly.outer);
          if (!ring_of(poly.outer, 0, n, all)) {
            ++bad;
            continue;
          }
          for (std::size_t k = 2; k < n; ++k) {
            if (pr.type == PrimType::Trifans) {
              ring = {all[0], all[k - 1], all[k]};
            } else if (k % 2 == 0) {
              ring = {all[k - 2], all[k - 1], all[k]};
            } else {
              ring = {all[k - 1], all[k - 2], all[k]};  // keep the winding of a strip
            }
            add(ring, {});
          }
        }
        break;
      }
    }
    if (bad)
      p_.problem("BAD_INDICES", where + ": " + std::to_string(bad) +
                                    " face(s) with indices out of range or counts that do not add up were skipped");
  }

  void add(const std::vector<std::uint32_t>& outer, const std::vector<std::vector<std::uint32_t>>& holes) {
    MeshFace f;
    f.first_ring = static_cast<std::uint32_t>(mesh_.ring_count());
    f.ring_count = static_cast<std::uint32_t>(1 + holes.size());
    f.kind = SurfaceKind::Unknown;
    f.lod = 255;
    mesh_.indices.insert(mesh_.indices.end(), outer.begin(), outer.end());
    mesh_.ring_offsets.push_back(static_cast<std::uint32_t>(mesh_.indices.size()));
    for (const auto& h : holes) {
      mesh_.indices.insert(mesh_.indices.end(), h.begin(), h.end());
      mesh_.ring_offsets.push_back(static_cast<std::uint32_t>(mesh_.indices.size()));
    }
    mesh_.faces.push_back(f);
    ++info_.faces;
  }

  static constexpr std::size_t kMaxVisits = 1'000'000;
  Parser& p_;
  const ColladaOptions& opt_;
  ColladaInfo& info_;
  Mesh& mesh_;
  std::size_t visits_ = 0;
  bool stopped_ = false, depth_reported_ = false;
};

template <class Feed>
Mesh read_with(const std::string& name, const std::string& source_id, const ColladaOptions& options,
               std::vector<Problem>& problems, ColladaInfo& info, Feed&& feed) {
  info = ColladaInfo{};
  info.file = name;
  Parser parser(name, problems, info, source_id);
  xml::SafeParser xml(name, parser, options.max_xml_depth);
  parser.attach(&xml);
  feed(xml);
  Mesh mesh;
  mesh.source_id = source_id;
  mesh.source_file = name;
  Builder(parser, options, info, mesh).build();
  if (mesh.faces.empty())
    problems.push_back(Problem{source_id, name, "read", "NO_GEOMETRY",
                               "the COLLADA scene instantiates no polygon geometry"});
  return mesh;
}

}  // namespace

namespace detail {

Mesh read_collada_bounded(const std::string& path, const std::string& display, const std::string& source_id,
                          const ColladaOptions& options, xml::ByteBudget& budget, std::vector<Problem>& problems,
                          ColladaInfo& info) {
  return read_with(display, source_id, options, problems, info,
                   [&](xml::SafeParser& p) { xml::parse_vsi_file(path, display, p, budget); });
}

}  // namespace detail

Mesh read_collada(const std::string& path, const std::string& source_id, const ColladaOptions& options,
                  std::vector<Problem>& problems, ColladaInfo& info) {
  xml::ByteBudget budget;
  budget.max_entry_bytes = options.max_bytes;
  budget.max_total_bytes = options.max_bytes;
  return detail::read_collada_bounded(path, path, source_id, options, budget, problems, info);
}

Mesh read_collada_buffer(std::string_view xml, const std::string& name, const std::string& source_id,
                         const ColladaOptions& options, std::vector<Problem>& problems, ColladaInfo& info) {
  return read_with(name, source_id, options, problems, info,
                   [&](xml::SafeParser& p) { p.feed(xml.data(), xml.size(), true); });
}

}  // namespace groundplan::gis

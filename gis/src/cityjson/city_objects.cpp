// SPDX-License-Identifier: MIT
// City object -> Mesh (issue 16). CityJSON boundaries are nested arrays of vertex indices whose depth
// the geometry type fixes (CityJSON 2.0 spec §3.3): MultiSurface/CompositeSurface [surface][ring][i],
// Solid [shell][surface][ring][i], MultiSolid/CompositeSolid [solid][shell][surface][ring][i];
// "semantics.values" mirrors boundaries down to the surface and holds an index into
// "semantics.surfaces" (or null). A GeometryInstance places a template: vertex = M * template vertex
// + the instance's reference point (its one boundary index).
#include "cityjson/city_objects.h"
#include "coordinate_limit.h"

#include <groundplan/error.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace groundplan::gis::cityjson {
namespace {

namespace dom = simdjson::dom;

SurfaceKind kind_of(std::string_view type) {
  if (type == "GroundSurface") return SurfaceKind::Ground;
  if (type == "RoofSurface") return SurfaceKind::Roof;
  if (type == "WallSurface") return SurfaceKind::Wall;
  if (type == "ClosureSurface") return SurfaceKind::Closure;
  return SurfaceKind::Other;
}

/// Surface levels above a surface in "boundaries" (and "semantics.values"); -1: not a surface type.
int surface_levels(std::string_view type) {
  if (type == "MultiSurface" || type == "CompositeSurface") return 1;
  if (type == "Solid") return 2;
  if (type == "MultiSolid" || type == "CompositeSolid") return 3;
  return -1;
}

/// "lod": "2", "2.2" (1.1, 2.0) or a number 2, 1.2 (1.0). major 0..4, minor 0..9.
bool parse_lod(dom::element e, int& major, int& minor) {
  std::string_view s;
  double d = 0;
  if (e.get_string().get(s) == simdjson::SUCCESS) {
    if (s.size() == 1 && s[0] >= '0' && s[0] <= '4') {
      major = s[0] - '0';
      minor = 0;
      return true;
    }
    if (s.size() == 3 && s[0] >= '0' && s[0] <= '4' && s[1] == '.' && s[2] >= '0' && s[2] <= '9') {
      major = s[0] - '0';
      minor = s[2] - '0';
      return true;
    }
    return false;
  }
  if (e.get_double().get(d) != simdjson::SUCCESS || !(d >= 0 && d < 5)) return false;
  major = static_cast<int>(d);
  minor = static_cast<int>(std::lround((d - major) * 10));
  if (minor > 9) return false;
  return true;
}

/// Defects of one object: one Problem per code, with the count and the first case.
struct Defects {
  struct Entry {
    std::string code, first;
    std::size_t count = 0;
  };
  std::vector<Entry> entries;
  void add(const char* code, std::string reason) {
    for (Entry& e : entries)
      if (e.code == code) {
        ++e.count;
        return;
      }
    entries.push_back(Entry{code, std::move(reason), 1});
  }
};

/// Where a geometry's indices point, and how its vertices are placed (templates).
struct VertexSource {
  const std::vector<Point3>* points = nullptr;
  const std::uint8_t* defects = nullptr;  // VertexTable::defects of `points` where there is no matrix
  const double* matrix = nullptr;  // row-major 4x4 (GeometryInstance), or none
  Point3 ref;
};

class GeometryWalker {
 public:
  GeometryWalker(const VertexSource& src, const std::vector<SurfaceKind>& kinds, std::uint8_t lod, double max_abs,
                 Mesh& mesh, Defects& defects)
      : src_(src), kinds_(kinds), lod_(lod), max_abs_(max_abs), mesh_(mesh), defects_(defects) {}

  void walk(dom::element boundaries, std::optional<dom::element> values, int levels) {
    if (levels == 0) {
      SurfaceKind kind = SurfaceKind::Unknown;
      std::uint64_t k = 0;
      if (values && values->get_uint64().get(k) == simdjson::SUCCESS) {
        if (k < kinds_.size())
          kind = kinds_[k];
        else
          defects_.add("BAD_SEMANTICS", "semantics value " + std::to_string(k) + " has no surface (" +
                                            std::to_string(kinds_.size()) + " declared)");
      }
      surface(boundaries, kind);
      return;
    }
    dom::array children = boundaries.get_array();
    // The semantic values run beside the boundaries: one iterator each (dom::array::at is a linear scan,
    // which made a MultiSurface of n surfaces cost n^2).
    dom::array value_children;
    const bool have_values = values && values->get_array().get(value_children) == simdjson::SUCCESS;
    auto value_it = have_values ? value_children.begin() : dom::array::iterator{};
    const auto value_end = have_values ? value_children.end() : dom::array::iterator{};
    for (dom::element child : children) {
      std::optional<dom::element> v;
      if (have_values && value_it != value_end) {
        v = *value_it;
        ++value_it;
      }
      walk(child, v, levels - 1);
    }
  }

 private:
  enum class VertexDefect { None, BadIndex, NotFinite, OutOfRange };

  VertexDefect vertex(std::uint64_t index, Point3& out) const {
    if (index >= src_.points->size()) return VertexDefect::BadIndex;
    if (!src_.matrix) {  // checked once per vertex by VertexTable::classify
      switch (src_.defects[index]) {
        case VertexTable::kOk: out = (*src_.points)[index]; return VertexDefect::None;
        case VertexTable::kNotFinite: return VertexDefect::NotFinite;
        default: return VertexDefect::OutOfRange;
      }
    }
    Point3 p = (*src_.points)[index];
    {
      const double* m = src_.matrix;
      p = Point3{m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3] + src_.ref.x,
                 m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7] + src_.ref.y,
                 m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11] + src_.ref.z};
    }
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return VertexDefect::NotFinite;
    if (std::fabs(p.x) > max_abs_ || std::fabs(p.y) > max_abs_ || std::fabs(p.z) > max_abs_)
      return VertexDefect::OutOfRange;
    out = p;
    return VertexDefect::None;
  }

  /// Rings and face go straight into the mesh; a surface dropped half way (a bad index, a too short outer
  /// ring, malformed JSON thrown out of the walk) is taken out again when the writer goes out of scope.
  class FaceWriter {
   public:
    explicit FaceWriter(Mesh& m)
        : m_(m), vertices_(m.vertices.size()), indices_(m.indices.size()), rings_(m.ring_offsets.size()) {}
    ~FaceWriter() {
      if (done_) return;
      m_.vertices.resize(vertices_);
      m_.indices.resize(indices_);
      m_.ring_offsets.resize(rings_);
    }
    std::size_t ring_mark() const { return m_.vertices.size(); }
    /// Room for `n` more points, growing geometrically (a hint: point() still checks).
    void make_room(std::size_t n) {
      if (m_.vertices.capacity() - m_.vertices.size() < n)
        m_.vertices.reserve(std::max(m_.vertices.size() + n, 2 * m_.vertices.capacity()));
      if (m_.indices.capacity() - m_.indices.size() < n)
        m_.indices.reserve(std::max(m_.indices.size() + n, 2 * m_.indices.capacity()));
    }
    void point(const Point3& p) {
      m_.indices.push_back(static_cast<std::uint32_t>(m_.vertices.size()));
      m_.vertices.push_back(p);
    }
    void end_ring() { m_.ring_offsets.push_back(static_cast<std::uint32_t>(m_.indices.size())); }
    void drop_ring(std::size_t mark) {  // the points since ring_mark(), of a ring not ended
      m_.indices.resize(m_.indices.size() - (m_.vertices.size() - mark));
      m_.vertices.resize(mark);
    }
    std::size_t rings() const { return m_.ring_offsets.size() - rings_; }
    void end_face(SurfaceKind kind, std::uint8_t lod) {
      MeshFace f;
      f.first_ring = static_cast<std::uint32_t>(rings_ - 1);
      f.ring_count = static_cast<std::uint32_t>(rings());
      f.kind = kind;
      f.lod = lod;
      m_.faces.push_back(f);
      done_ = true;
    }

   private:
    Mesh& m_;
    std::size_t vertices_, indices_, rings_;
    bool done_ = false;
  };

  /// The hot loop (~3/4 of the walk's instructions): points of the ring from `it` while they are indices of
  /// good vertices of a geometry without a matrix, each checked once by VertexTable::classify. Returns
  /// true at the ring's end; false at an element that needs a closer look (left at `it`).
  [[gnu::flatten]] bool easy_points(dom::array::iterator& it, const dom::array::iterator& end, FaceWriter& face,
                                    std::uint64_t& i) const {
    if (src_.matrix) return it == end;
    const Point3* points = src_.points->data();
    const std::size_t n = src_.points->size();
    const std::uint8_t* defects = src_.defects;
    for (; it != end; ++it) {
      if ((*it).get_uint64().get(i) != simdjson::SUCCESS || i >= n || defects[i] != VertexTable::kOk) return false;
      face.point(points[i]);
    }
    return true;
  }

  void surface(dom::element s, SurfaceKind kind) {
    FaceWriter face(mesh_);
    std::size_t ring_no = 0;
    for (dom::element ring : s.get_array()) {
      const std::size_t mark = face.ring_mark();
      const dom::array indices = ring.get_array();
      face.make_room(indices.size());
      std::uint64_t i = 0;
      for (dom::array::iterator it = indices.begin(), end = indices.end(); it != end; ++it) {
        if (easy_points(it, end, face, i)) break;  // the ring's end
        // *it is not an index of a good vertex without a matrix: what is it?
        Point3 p;
        if ((*it).get_uint64().get(i) != simdjson::SUCCESS) {
          defects_.add("BAD_VERTEX_INDEX", "a vertex index is not a non-negative integer; its surface is dropped");
          return;
        }
        if (const VertexDefect d = vertex(i, p); d != VertexDefect::None) {
          if (d == VertexDefect::BadIndex)
            defects_.add("BAD_VERTEX_INDEX", "vertex index " + std::to_string(i) + " is out of range (" +
                                                 std::to_string(src_.points->size()) +
                                                 " vertices); its surface is dropped");
          else if (d == VertexDefect::NotFinite)
            defects_.add("NOT_FINITE", "vertex " + std::to_string(i) +
                                           " is not three finite numbers; its surface is dropped");
          else
            defects_.add("COORDINATE_OUT_OF_RANGE", "vertex " + std::to_string(i) + ": " +
                                                        beyond_coordinate_limit(max_abs_) +
                                                        "; its surface is dropped");
          return;
        }
        face.point(p);
      }
      const std::size_t n = face.ring_mark() - mark;
      if (n < 3) {
        defects_.add("TOO_FEW_POINTS", std::string("a ") + (ring_no == 0 ? "surface's outer ring" : "hole") + " has " +
                                           std::to_string(n) + " vertices (< 3); it is dropped");
        if (ring_no == 0) return;
        face.drop_ring(mark);
      } else {
        face.end_ring();
      }
      ++ring_no;
    }
    if (face.rings() == 0) {
      defects_.add("TOO_FEW_POINTS", "a surface has no ring; it is dropped");
      return;
    }
    face.end_face(kind, lod_);
  }

  const VertexSource& src_;
  const std::vector<SurfaceKind>& kinds_;
  std::uint8_t lod_;
  double max_abs_;
  Mesh& mesh_;
  Defects& defects_;
};

void semantic_kinds(const GeometryFields& geometry, std::vector<SurfaceKind>& kinds, std::optional<dom::element>& values) {
  kinds.clear();
  dom::element sem;
  if (geometry.get(geometry.semantics).get(sem) != simdjson::SUCCESS || sem.is_null()) return;
  dom::element surfaces;
  if (sem["surfaces"].get(surfaces) == simdjson::SUCCESS)
    for (dom::element s : surfaces.get_array()) {
      std::string_view t;
      kinds.push_back(s["type"].get(t) == simdjson::SUCCESS ? kind_of(t) : SurfaceKind::Other);
    }
  dom::element v;
  if (sem["values"].get(v) == simdjson::SUCCESS) values = v;
}

}  // namespace

GeometryFields::GeometryFields(dom::element geometry) {
  dom::object o;
  if ((object_error = geometry.get_object().get(o)) != simdjson::SUCCESS) return;
  for (dom::key_value_pair f : o) {
    const std::string_view k = f.key;
    Field* slot = nullptr;
    if (k == "boundaries") slot = &boundaries;
    else if (k == "type") slot = &type;
    else if (k == "lod") slot = &lod;
    else if (k == "semantics") slot = &semantics;
    else if (k == "template") slot = &template_index;
    else if (k == "transformationMatrix") slot = &matrix;
    if (slot && !slot->found) *slot = Field{f.value, true};  // the first, as a lookup by key finds
  }
}

void VertexTable::classify(double max_abs) {
  defects.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point3& p = points[i];
    defects[i] = !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) ? kNotFinite
                 : std::fabs(p.x) > max_abs || std::fabs(p.y) > max_abs || std::fabs(p.z) > max_abs ? kOutOfRange
                                                                                                   : kOk;
  }
}

Transform parse_transform(dom::element e, const std::string& file) {
  Transform t;
  try {
    dom::array scale = e["scale"].get_array();
    dom::array translate = e["translate"].get_array();
    if (scale.size() != 3 || translate.size() != 3) throw InputError(file + ": \"transform\" needs 3 scale and 3 translate values");
    for (std::size_t i = 0; i < 3; ++i) {
      t.scale[i] = scale.at(i).get_double();
      t.translate[i] = translate.at(i).get_double();
      if (!std::isfinite(t.scale[i]) || !std::isfinite(t.translate[i]) || t.scale[i] == 0)
        throw InputError(file + ": \"transform\" has a zero or non-finite value");
    }
  } catch (const simdjson::simdjson_error& err) {
    throw InputError(file + ": \"transform\" is not {\"scale\": [3 numbers], \"translate\": [3 numbers]} (" +
                     err.what() + ")");
  }
  t.present = true;
  return t;
}

Templates parse_templates(dom::element e, const std::string& file, std::vector<Problem>& problems) {
  Templates t;
  try {
    for (dom::element g : e["templates"].get_array()) t.geometries.push_back(g);
    for (dom::element v : e["vertices-templates"].get_array()) {
      dom::array a = v.get_array();
      double xyz[3] = {NAN, NAN, NAN};
      bool ok = a.size() == 3;
      for (std::size_t i = 0; ok && i < 3; ++i) ok = a.at(i).get_double().get(xyz[i]) == simdjson::SUCCESS;
      t.vertices.push_back(ok ? Point3{xyz[0], xyz[1], xyz[2]} : Point3{NAN, NAN, NAN});
    }
  } catch (const simdjson::simdjson_error& err) {
    problems.push_back(Problem{"", file, "read", "BAD_TEMPLATES",
                               std::string("\"geometry-templates\" is malformed (") + err.what() +
                                   "); GeometryInstances using it are dropped"});
  }
  return t;
}

void add_vertex(std::vector<Point3>& out, const double* xyz, bool ok, const Transform& t, std::size_t& bad) {
  if (!ok) {
    ++bad;
    out.push_back(Point3{NAN, NAN, NAN});
    return;
  }
  out.push_back(Point3{xyz[0] * t.scale[0] + t.translate[0], xyz[1] * t.scale[1] + t.translate[1],
                       xyz[2] * t.scale[2] + t.translate[2]});
}

void ObjectConverter::convert(std::string_view id_view, dom::element object, const VertexTable& vertices,
                              const Templates& templates) {
  ++info_.city_objects;
  // The members used, in one pass over the object's fields (a lookup by key scans them each time); the
  // first of a repeated key, as a lookup finds.
  dom::element type_el, parents_el, children_el, attributes_el, geometry_el;
  bool has_type = false, has_parents = false, has_children_el = false, has_attributes = false, has_geometry = false;
  dom::object fields;
  if (object.get_object().get(fields) == simdjson::SUCCESS)
    for (dom::key_value_pair f : fields) {
      const std::string_view k = f.key;
      if (k == "geometry") {
        if (!has_geometry) geometry_el = f.value, has_geometry = true;
      } else if (k == "type") {
        if (!has_type) type_el = f.value, has_type = true;
      } else if (k == "parents") {
        if (!has_parents) parents_el = f.value, has_parents = true;
      } else if (k == "children") {
        if (!has_children_el) children_el = f.value, has_children_el = true;
      } else if (k == "attributes") {
        if (!has_attributes) attributes_el = f.value, has_attributes = true;
      }
    }
  std::string_view type;
  if (!has_type || type_el.get_string().get(type) != simdjson::SUCCESS) {
    const std::string id(id_view.substr(0, 256));
    problems_.push_back(Problem{id, file_, "read", "BAD_CITYOBJECT", "city object \"" + id + "\" has no \"type\"; skipped"});
    return;
  }
  const bool part = type == "BuildingPart";
  if (type != "Building" && !part) return;  // other city objects are not buildings
  ++(part ? info_.building_parts : info_.buildings);

  // Built in the thread's scratch mesh, whose arrays keep their capacity from one object to the next, and
  // handed on as an exact-size copy: four allocations an object instead of one per growth step.
  // (A thread that met one huge object does not keep its arrays: over 1M vertices they are let go.)
  thread_local Mesh scratch;
  if (scratch.vertices.capacity() > (std::size_t{1} << 20)) scratch = Mesh{};
  Mesh& mesh = scratch;
  mesh.vertices.clear();
  mesh.indices.clear();
  mesh.ring_offsets.assign(1, 0);
  mesh.faces.clear();
  mesh.source_id.assign(id_view.substr(0, 256));  // into the kept capacity; `id` below is this string
  mesh.parent_id.clear();
  mesh.name.clear();
  mesh.measured_height = -1;
  mesh.source_file = file_;
  const std::string& id = mesh.source_id;
  Defects defects;
  bool has_children = false;
  std::string skipped_types;  // geometry types that are not surfaces (MultiPoint, MultiLineString)
  std::vector<Candidate>& candidates = candidates_;
  candidates.clear();
  try {
    dom::array arr;
    if (part && has_parents && parents_el.get_array().get(arr) == simdjson::SUCCESS && arr.size() > 0) {
      std::string_view parent;
      if ((*arr.begin()).get_string().get(parent) == simdjson::SUCCESS) mesh.parent_id = std::string(parent.substr(0, 256));
    }
    if (has_children_el && children_el.get_array().get(arr) == simdjson::SUCCESS) has_children = arr.size() > 0;
    double h = 0;
    if (has_attributes && attributes_el["measuredHeight"].get_double().get(h) == simdjson::SUCCESS && std::isfinite(h))
      mesh.measured_height = h;
    if (has_geometry && geometry_el.get_array().get(arr) == simdjson::SUCCESS) {
      for (dom::element g : arr) {
        try {
          Candidate c;
          const GeometryFields fields_of_g(g);
          std::string_view gtype = fields_of_g.get(fields_of_g.type).get_string();
          c.geometry = fields_of_g;
          if (gtype == "GeometryInstance") {
            const std::uint64_t tpl = fields_of_g.get(fields_of_g.template_index).get_uint64();
            if (tpl >= templates.geometries.size()) {
              defects.add("BAD_TEMPLATE", "GeometryInstance names template " + std::to_string(tpl) + " of " +
                                              std::to_string(templates.geometries.size()) + "; it is dropped");
              continue;
            }
            c.geometry = GeometryFields(templates.geometries[tpl]);
            gtype = c.geometry.get(c.geometry.type).get_string();
            dom::array m = fields_of_g.get(fields_of_g.matrix).get_array();
            if (m.size() != 16) {
              defects.add("BAD_TEMPLATE", "a GeometryInstance's transformationMatrix does not have 16 values; dropped");
              continue;
            }
            std::size_t i = 0;
            for (dom::element e : m) c.matrix[i++] = e.get_double();
            dom::array b = fields_of_g.get(fields_of_g.boundaries).get_array();
            if (b.size() != 1) {
              defects.add("BAD_TEMPLATE", "a GeometryInstance's boundaries must hold one reference vertex; dropped");
              continue;
            }
            c.ref_index = (*b.begin()).get_uint64();
            c.instance = true;
          }
          c.levels = surface_levels(gtype);
          if (c.levels < 0) {
            if (skipped_types.find(gtype) == std::string::npos)
              skipped_types += (skipped_types.empty() ? "" : ", ") + std::string(gtype.substr(0, 40));
            continue;
          }
          dom::element lod_el;
          if (c.geometry.get(c.geometry.lod).get(lod_el) != simdjson::SUCCESS || !parse_lod(lod_el, c.major, c.minor)) {
            defects.add("BAD_LOD", "a " + std::string(gtype) + " has no valid \"lod\" (\"0\"..\"4\" or \"2.2\" ...); "
                                   "it is dropped");
            continue;
          }
          candidates.push_back(c);
        } catch (const simdjson::simdjson_error& err) {
          defects.add("BAD_GEOMETRY", std::string("a geometry is malformed (") + err.what() + "); it is dropped");
        }
      }
    }
  } catch (const simdjson::simdjson_error& err) {
    defects.add("BAD_CITYOBJECT", std::string("the object is malformed (") + err.what() + ")");
  }
  auto report_defects = [&] {
    for (const Defects::Entry& e : defects.entries)
      problems_.push_back(Problem{id, file_, "read", e.code,
                                  e.count == 1 ? e.first : e.first + " (and " + std::to_string(e.count - 1) + " more)"});
  };
  auto give_up = [&](const char* code, const std::string& reason) {
    report_defects();
    problems_.push_back(Problem{id, file_, "read", code, reason});
    ++info_.buildings_dropped;
  };

  // LoD choice: the highest the object has, or the one asked for (refinement: "2.2" of LoD 2).
  int best = -1;
  std::string available;
  for (const Candidate& c : candidates) {
    std::string name = std::to_string(c.major);
    if (c.minor) name += '.' + std::to_string(c.minor);  // not "." + ...: GCC 12's -Wrestrict false positive
    if (available.find(name) == std::string::npos) available += (available.empty() ? "" : ", ") + name;
    if (opt_.lod >= 0 && (c.major != opt_.lod || (opt_.lod_refinement >= 0 && c.minor != opt_.lod_refinement))) continue;
    best = std::max(best, c.rank());
  }
  if (candidates.empty()) {
    if (has_children && defects.entries.empty() && skipped_types.empty()) return;  // its parts carry it
    std::string reason = std::string(part ? "BuildingPart" : "Building") + " \"" + id + "\" has no surface geometry";
    if (!skipped_types.empty()) reason += " (only " + skipped_types + ")";
    if (!defects.entries.empty()) reason += " left after the defects above";
    give_up("NO_GEOMETRY", reason);
    return;
  }
  if (best < 0) {
    if (has_children) {
      report_defects();
      return;
    }
    const std::string want = std::to_string(opt_.lod) + (opt_.lod_refinement >= 0 ? "." + std::to_string(opt_.lod_refinement) : "");
    give_up("NO_GEOMETRY_AT_LOD", "no geometry at LoD " + want + " (the object has LoD " + available + ")");
    return;
  }

  for (const Candidate& c : candidates) {
    if (c.rank() != best) continue;
    try {
      VertexSource src;
      src.points = &vertices.points;
      src.defects = vertices.defects.data();
      if (c.instance) {
        if (c.ref_index >= vertices.points.size() || !std::isfinite(vertices.points[c.ref_index].x)) {
          defects.add("BAD_VERTEX_INDEX", "a GeometryInstance's reference vertex " + std::to_string(c.ref_index) +
                                              " is out of range or not finite; it is dropped");
          continue;
        }
        src.points = &templates.vertices;
        src.matrix = c.matrix;
        src.ref = vertices.points[c.ref_index];
      }
      std::optional<dom::element> values;
      semantic_kinds(c.geometry, kinds_, values);
      GeometryWalker walker(src, kinds_, static_cast<std::uint8_t>(c.major), opt_.max_abs_coordinate, mesh, defects);
      walker.walk(c.geometry.get(c.geometry.boundaries), values, c.levels);
    } catch (const simdjson::simdjson_error& err) {
      defects.add("BAD_GEOMETRY", std::string("a geometry's boundaries are malformed (") + err.what() +
                                      "); what was read of it is kept");
    }
  }
  if (mesh.faces.empty()) {
    give_up("NO_GEOMETRY", std::string(part ? "BuildingPart" : "Building") + " \"" + id +
                               "\" has no usable surface left after the defects above");
    return;
  }
  report_defects();
  ++info_.meshes;
  on_mesh_(Mesh(mesh));
}

}  // namespace groundplan::gis::cityjson

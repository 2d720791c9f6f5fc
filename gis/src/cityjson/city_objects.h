// SPDX-License-Identifier: MIT
#pragma once
// One CityJSON city object (a simdjson DOM element) into a Mesh: geometry types, semantics, LoD
// choice, geometry templates. Shared by the CityJSON and the CityJSONSeq front ends (issue 16).
#include <groundplan/gis/cityjson.h>
#include <groundplan/mesh.h>

#include <simdjson.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis::cityjson {

/// "transform": vertex = integer * scale + translate.
struct Transform {
  bool present = false;
  double scale[3] = {1, 1, 1};
  double translate[3] = {0, 0, 0};
};

/// "geometry-templates": template geometries (DOM elements, valid while their parser lives) and their
/// vertices (real coordinates, no transform).
struct Templates {
  std::vector<simdjson::dom::element> geometries;
  std::vector<Point3> vertices;
};

/// Reads "transform"; throws InputError (naming `file`) when it is not {scale:[3 numbers], translate:[3 numbers]}.
Transform parse_transform(simdjson::dom::element e, const std::string& file);
/// Reads "geometry-templates"; a malformed entry gives a Problem and an empty template.
Templates parse_templates(simdjson::dom::element e, const std::string& file, std::vector<Problem>& problems);
/// Appends one vertex from three numbers as written; a vertex that is not three finite numbers becomes
/// NaN (the surfaces using it are dropped with a Problem) and `bad` counts it.
void add_vertex(std::vector<Point3>& out, const double* xyz, bool ok, const Transform& t, std::size_t& bad);

/// A file's (or a CityJSONSeq feature's) vertices with the verdict on each, found once per vertex rather
/// than once per use: a vertex is used by ~3 surfaces, and the check was a third of the walk.
struct VertexTable {
  enum Defect : std::uint8_t { kOk = 0, kNotFinite = 1, kOutOfRange = 2 };
  std::vector<Point3> points;
  std::vector<std::uint8_t> defects;  // one per point, after classify()
  /// Sets `defects` from `points`: not finite, else beyond `max_abs` in any axis, else ok.
  void classify(double max_abs);
};

/// The members of a geometry object the reader uses, found in one pass over its fields. get() answers as
/// simdjson's `geometry["key"]` does (INCORRECT_TYPE when the geometry is not an object, NO_SUCH_FIELD,
/// else the first such member), so that the error messages stay those of a lookup by key.
struct GeometryFields {
  struct Field {
    simdjson::dom::element element;
    bool found = false;
  };
  simdjson::error_code object_error = simdjson::SUCCESS;
  Field type, lod, boundaries, semantics, template_index, matrix;
  explicit GeometryFields(simdjson::dom::element geometry);
  GeometryFields() = default;
  simdjson::simdjson_result<simdjson::dom::element> get(const Field& f) const {
    if (object_error != simdjson::SUCCESS) return object_error;
    if (!f.found) return simdjson::NO_SUCH_FIELD;
    return simdjson::dom::element(f.element);
  }
};

/// A geometry with its LoD, resolved through a template where it is a GeometryInstance.
struct Candidate {
  GeometryFields geometry;  // the surface geometry (the template for an instance)
  int levels = 0;
  int major = 0, minor = 0;
  bool instance = false;
  double matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::uint64_t ref_index = 0;
  int rank() const { return major * 10 + minor; }
};

/// Turns city objects into meshes. Holds no state between objects but the sinks.
class ObjectConverter {
 public:
  ObjectConverter(const std::string& file, const CityJsonOptions& options, const MeshCallback& on_mesh,
                  std::vector<Problem>& problems, CityJsonInfo& info)
      : file_(file), opt_(options), on_mesh_(on_mesh), problems_(problems), info_(info) {}

  /// One city object `id` whose vertex indices point into `vertices` (classified). Objects that are not
  /// Building / BuildingPart are counted and skipped. A malformed object is a Problem; never throws
  /// simdjson errors.
  void convert(std::string_view id, simdjson::dom::element object, const VertexTable& vertices,
               const Templates& templates);

 private:
  const std::string& file_;
  const CityJsonOptions& opt_;
  const MeshCallback& on_mesh_;
  std::vector<Problem>& problems_;
  CityJsonInfo& info_;
  // Kept from one object to the next (no allocation per object or geometry).
  std::vector<Candidate> candidates_;
  std::vector<SurfaceKind> kinds_;
};

}  // namespace groundplan::gis::cityjson

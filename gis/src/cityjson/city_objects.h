// SPDX-License-Identifier: MIT
#pragma once
// One CityJSON city object (a simdjson DOM element) into a Mesh: geometry types, semantics, LoD
// choice, geometry templates. Shared by the CityJSON and the CityJSONSeq front ends (issue 16).
#include <groundplan/gis/cityjson.h>
#include <groundplan/mesh.h>

#include <simdjson.h>

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

/// Turns city objects into meshes. Holds no state between objects but the sinks.
class ObjectConverter {
 public:
  ObjectConverter(const std::string& file, const CityJsonOptions& options, const MeshCallback& on_mesh,
                  std::vector<Problem>& problems, CityJsonInfo& info)
      : file_(file), opt_(options), on_mesh_(on_mesh), problems_(problems), info_(info) {}

  /// One city object `id` whose vertex indices point into `vertices`. Objects that are not Building /
  /// BuildingPart are counted and skipped. A malformed object is a Problem; never throws simdjson errors.
  void convert(std::string_view id, simdjson::dom::element object, const std::vector<Point3>& vertices,
               const Templates& templates);

 private:
  const std::string& file_;
  const CityJsonOptions& opt_;
  const MeshCallback& on_mesh_;
  std::vector<Problem>& problems_;
  CityJsonInfo& info_;
};

}  // namespace groundplan::gis::cityjson

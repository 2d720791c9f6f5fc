// SPDX-License-Identifier: MIT
#pragma once
// COLLADA 1.4 / 1.5 (.dae) geometry reader (DESIGN.md stage 1, issue 6): the scene a document
// instantiates (scene/instance_visual_scene, else its first visual_scene) as ONE mesh, every
// instance_geometry placed by its node's transforms (matrix, translate, rotate, scale, in document
// order, parents first) and instance_node (library_nodes, any node with an id) followed to a bounded
// depth. Primitives: triangles, polylist, polygons (with <ph> holes), trifans, tristrips; the VERTEX
// input's offset is used and the largest input offset + 1 is the index stride.
//
// Output frame: the model's local metric frame, x east, y north, z up, metres: <unit meter="..."/>
// is applied (the meter factor is trusted, not the name) and <up_axis> Y_UP / X_UP is turned to
// Z_UP. Faces are SurfaceKind::Unknown, lod 255. Materials, textures, normals are not read.
//
// Security: the XML rules of the other readers (no DTD, no entities, depth limit); sizes bounded
// by xml::ByteBudget (the caller's); indices, counts and strides are checked: a bad primitive
// becomes a Problem (stage "read"), never a crash.
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis {

struct ColladaOptions {
  std::size_t max_xml_depth = 256;
  /// Nested instance_node / node levels followed before the rest is a Problem (cycles end here too).
  int max_instance_depth = 32;
  /// Vertices the scene may expand to (instances multiply geometry); beyond it a Problem.
  std::size_t max_vertices = 20'000'000;
  /// Unpacked bytes of the document (read_collada only).
  std::uint64_t max_bytes = std::uint64_t{256} << 20;
};

struct ColladaInfo {
  std::string file;
  std::string version;       // "1.4.1", "1.5.0" as written
  double unit_m = 1.0;       // <unit meter>
  std::string up_axis = "Y_UP";
  std::size_t geometries = 0;           // <geometry> elements with a <mesh>
  std::size_t geometry_instances = 0;   // instance_geometry placed
  std::size_t node_instances = 0;       // instance_node followed
  std::size_t faces = 0;
};

/// Reads `path` (a local or GDAL VSI path: /vsizip/a.kmz/models/b.dae). `source_id` goes to
/// Mesh::source_id. Throws InputError naming the file when it cannot be read, is not well-formed,
/// hostile, or not COLLADA. Per-primitive defects (indices out of range, odd counts) are Problems.
Mesh read_collada(const std::string& path, const std::string& source_id, const ColladaOptions& options,
                  std::vector<Problem>& problems, ColladaInfo& info);

/// The same on a document in memory; `name` stands for the file in messages and Mesh::source_file.
Mesh read_collada_buffer(std::string_view xml, const std::string& name, const std::string& source_id,
                         const ColladaOptions& options, std::vector<Problem>& problems, ColladaInfo& info);

}  // namespace groundplan::gis

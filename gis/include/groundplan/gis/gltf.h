// SPDX-License-Identifier: MIT
#pragma once
// glTF 2.0 / GLB reader through tinygltf (DESIGN.md stage 1, issue 6): the default scene (else
// scene 0, else every root node), one Mesh per node that has a mesh, its primitives (TRIANGLES,
// TRIANGLE_STRIP, TRIANGLE_FAN; indexed or not) placed by the node transforms (matrix or TRS),
// then turned from glTF's y-up to z-up as 3D Tiles does: (x, y, z) -> (x, -z, y).
//
// Compressed and quantized glTF (KHR_draco_mesh_compression, EXT_/KHR_meshopt_compression,
// KHR_mesh_quantization) is decoded first; a file that requires any other extension that changes
// geometry is refused with an InputError naming it.
//
// Buildings by feature: where a primitive has per-vertex feature ids (EXT_mesh_features by attribute,
// 3D Tiles 1.0's _BATCHID), each feature is one building (one Mesh over every node and primitive),
// named by its EXT_structural_metadata property table's gml_id, id or name (GltfOptions::id_field), else
// "feature #N"; triangles go to the feature of their first vertex. Without feature ids: one Mesh per node,
// named by the node, else by its nearest named ancestor, else "node N". A node with EXT_mesh_gpu_instancing
// gives one building per instance (its TRS in the node's frame), named by its EXT_instance_features id in the
// property table, else "<node> #<instance>".
//
// Georeference: the CESIUM_RTC extension's ECEF centre is added to every position; a mesh whose
// transformed positions lie at the Earth's radius (a 3D-Tiles-style ECEF root transform) is ECEF
// too. Anything else is in a local frame (x east, y north, z up, metres) that needs an origin.
//
// Security: tinygltf reads external buffers only through our callbacks: inside the glTF's folder
// tree (no "..", no absolute paths, no URLs, symlinks resolved), bounded in bytes. Images are never
// read or decoded. Every accessor, buffer view and index is bounds-checked: a bad primitive is a
// Problem, never a crash.
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::gis {

struct GltfOptions {
  std::uint64_t max_bytes = std::uint64_t{1} << 30;  // the file plus its external buffers
  std::size_t max_vertices = 50'000'000;             // over all meshes
  int max_node_depth = 64;
  std::string id_field;         // the property naming a feature (property table, batch table); "": gml_id, id, name
};

enum class GltfFrame {
  Local,  // x east, y north, z up, metres, relative to an origin the user gives
  Ecef,   // WGS 84 earth-centred, earth-fixed metres
};

struct GltfInfo {
  std::string file;
  std::string georeference;  // "CESIUM_RTC", "ECEF node transform", or "" (none: needs an origin)
  std::size_t nodes = 0;        // nodes visited
  std::size_t meshes = 0;       // meshes delivered
  std::size_t primitives = 0;   // primitives read
  std::size_t faces = 0;
  bool by_feature = false;      // buildings were split by feature id
};

/// How a 3D Tiles content places and names its glTF (tiles3d.h): ECEF = transform * RTC centre *
/// (y-up to z-up) * node transforms.
struct GltfTile {
  std::array<double, 16> transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // row-major, z-up
  bool has_rtc_center = false;  // a b3dm feature table's RTC_CENTER
  Point3 rtc_center;
  std::string feature_prefix;   // a feature without an id property is "<prefix>#<feature id>"
  std::function<std::string(std::int64_t)> feature_name;  // a b3dm batch table's id of a feature; "" = none
  std::string building;         // non-empty: the whole model is one building of this id (an i3dm instance)
};

/// Called once per node with a mesh; the mesh's frame says how to place it. May be moved from.
using GltfMeshCallback = std::function<void(Mesh&&, GltfFrame)>;

/// Reads a .gltf (JSON, external or data-URI buffers) or .glb. Mesh::source_id is the node's name,
/// else "node N". Throws InputError naming the file when it cannot be read or parsed, or passes
/// the byte limit. Exceptions thrown by `on_mesh` propagate.
void read_gltf(const std::string& path, const GltfOptions& options, const GltfMeshCallback& on_mesh,
               std::vector<Problem>& problems, GltfInfo& info);

/// The same from bytes in memory (a GLB or glTF JSON; a 3D Tiles content's glTF). `path` names it in
/// messages and locates its external buffers, which must lie under `root_folder`. `tile` may be null.
void read_gltf_bytes(const std::string& path, const std::string& bytes, const std::string& root_folder,
                     const GltfOptions& options, const GltfTile* tile, const GltfMeshCallback& on_mesh,
                     std::vector<Problem>& problems, GltfInfo& info);

/// The same model placed once per entry of `tiles` (parsed and decoded once): an i3dm's instances.
/// Without tiles, as read_gltf_bytes without a tile.
void read_gltf_instances(const std::string& path, const std::string& bytes, const std::string& root_folder,
                         const GltfOptions& options, const std::vector<GltfTile>& tiles, const GltfMeshCallback& on_mesh,
                         std::vector<Problem>& problems, GltfInfo& info);

}  // namespace groundplan::gis

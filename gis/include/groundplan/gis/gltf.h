// SPDX-License-Identifier: MIT
#pragma once
// glTF 2.0 / GLB reader through tinygltf (DESIGN.md stage 1, issue 6): the default scene (else
// scene 0, else every root node), one Mesh per node that has a mesh, its primitives (TRIANGLES,
// TRIANGLE_STRIP, TRIANGLE_FAN; indexed or not) placed by the node transforms (matrix or TRS),
// then turned from glTF's y-up to z-up as 3D Tiles does: (x, y, z) -> (x, -z, y).
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

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::gis {

struct GltfOptions {
  std::uint64_t max_bytes = std::uint64_t{1} << 30;  // the file plus its external buffers
  std::size_t max_vertices = 50'000'000;             // over all meshes
  int max_node_depth = 64;
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
};

/// Called once per node with a mesh; the mesh's frame says how to place it. May be moved from.
using GltfMeshCallback = std::function<void(Mesh&&, GltfFrame)>;

/// Reads a .gltf (JSON, external or data-URI buffers) or .glb. Mesh::source_id is the node's name,
/// else "node N". Throws InputError naming the file when it cannot be read or parsed, or passes
/// the byte limit. Exceptions thrown by `on_mesh` propagate.
void read_gltf(const std::string& path, const GltfOptions& options, const GltfMeshCallback& on_mesh,
               std::vector<Problem>& problems, GltfInfo& info);

}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
#pragma once
// Compressed glTF: KHR_draco_mesh_compression (Debian's libdraco), EXT_meshopt_compression and
// KHR_meshopt_compression (libmeshoptimizer); KHR_mesh_quantization needs nothing here (the reader
// reads integer and normalized positions). The compressed data is turned back into plain buffers,
// buffer views and accessors of the tinygltf model, so that the reader sees an uncompressed glTF
// and checks it as it checks any other. Everything is untrusted: every index, length and count is
// checked before it is used, and a decoder's failure is a problem of that primitive or that view.
#include <string>
#include <string_view>
#include <vector>

namespace tinygltf {
class Model;
}

namespace groundplan::gis::gltf {

/// tinygltf cannot load some compressed files as they are: a Draco primitive's indices accessor has no
/// buffer view (tinygltf refuses the file), and a meshopt fallback buffer has no data. Returns the glTF
/// JSON made loadable (a Draco primitive's "indices" dropped: decode() makes them from the Draco mesh;
/// a fallback buffer replaced by one byte of data), or an empty string when nothing needs changing.
/// Throws std::runtime_error when the JSON cannot be parsed (tinygltf would refuse it too).
std::string loadable_json(std::string_view json);

/// The extensions the file requires that groundplan does not read (anything but the compression and
/// quantization extensions above, CESIUM_RTC, EXT_mesh_features, EXT_structural_metadata,
/// EXT_mesh_gpu_instancing, EXT_instance_features and those of
/// materials and textures, which do not change geometry): reading it anyway would give wrong shapes.
std::vector<std::string> unknown_required_extensions(const tinygltf::Model& model);

/// Decompresses the model in place: meshopt buffer views into new buffers, Draco primitives into new
/// accessors (positions as float, indices as unsigned int, other attributes as float). Each failure is
/// one line in `problems` (the primitive or view is then left unreadable, and the reader skips it).
void decode(tinygltf::Model& model, std::vector<std::string>& problems);

}  // namespace groundplan::gis::gltf

// SPDX-License-Identifier: MIT
#pragma once
// One 3D Tiles content from its bytes: b3dm, cmpt (its inner tiles), glb or glTF JSON, each handed to
// the glTF reader with the tile's transform, RTC centre and batch table (tiles3d.h). Every header
// length is checked against the bytes there are.
#include <groundplan/gis/tiles3d.h>

#include <array>
#include <string>
#include <vector>

namespace groundplan::gis::tiles3d {

using Mat4 = std::array<double, 16>;  // row-major, z-up

/// Reads `bytes` (the content of `path`; external glTF buffers must lie under `root_folder`) placed by
/// `transform`. `label` names the tile's buildings that have no id of their own ("<label>#<feature>").
/// Throws InputError naming `path` for a content that cannot be read at all (a truncated header, a
/// length that lies, a format not read); what the glTF reader finds are Problems.
void read_content(const std::string& path, const std::string& label, const std::string& bytes,
                  const std::string& root_folder, const Mat4& transform, const Tiles3dOptions& options,
                  const GltfMeshCallback& on_mesh, std::vector<Problem>& problems, Tiles3dInfo& info, int depth = 0);

}  // namespace groundplan::gis::tiles3d

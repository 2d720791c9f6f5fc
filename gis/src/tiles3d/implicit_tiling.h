// SPDX-License-Identifier: MIT
#pragma once
// 3D Tiles 1.1 implicit tiling: a tile whose `implicitTiling` (QUADTREE or OCTREE) names subtree files by
// template; their availability bitstreams say which descendant tiles, contents and child subtrees exist.
// Walked depth first from the root, parents before children, only where tiles are available (bounded by
// the available bits, not by 4^levels). Untrusted: bitstreams shorter than their levels need, bad views,
// lengths that lie, levels past 31 are Problems (the subtree is then left out).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::gis::tiles3d {

struct ImplicitTiling {
  bool octree = false;
  int subtree_levels = 0, available_levels = 0;
  std::string subtrees;  // uri template of the subtree files ({level} {x} {y} {z})
  std::string content;   // uri template of the tiles' content; empty: the tiles have none
};

struct ImplicitTile {
  int level = 0;
  std::uint64_t x = 0, y = 0, z = 0;
  bool has_content = false;
  bool has_children = false;  // some child tile is available
};

/// The implicit tiling of `tile` (its implicitTiling and content uri); empty, or why it cannot be read.
std::string parse_implicit(const nlohmann::json& tile, ImplicitTiling& out);

/// `templ` with {level}, {x}, {y}, {z} replaced.
std::string expand(const std::string& templ, const ImplicitTile& t);

/// Reads a file that a uri names relative to `from` (a tileset or subtree file): its bytes and path, or
/// throws InputError (a uri outside the tileset, on the network ...).
using LoadFile = std::function<std::string(const std::string& from, const std::string& uri, std::string& path)>;

/// Walks the available tiles from the root subtree (`tileset` names the file the root tile is in): `visit`
/// is called for each, parents first, and says whether to go on into its children. Problems are strings
/// (`file: what`), each a subtree or a bitstream left out.
void walk_implicit(const ImplicitTiling& tiling, const std::string& tileset, const LoadFile& load,
                   const std::function<bool(const ImplicitTile&)>& visit, std::vector<std::pair<std::string, std::string>>& problems);

}  // namespace groundplan::gis::tiles3d

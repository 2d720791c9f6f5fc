// SPDX-License-Identifier: MIT
#pragma once
// OGC 3D Tiles (1.0 and 1.1) as input: a tileset.json, or one tile's content file (.b3dm, .cmpt,
// .glb/.gltf). The tile tree is walked from the root, each tile's `transform` composed down to its
// content; contents are b3dm (feature table RTC_CENTER and BATCH_LENGTH, JSON batch table, the glTF's
// _BATCHID), i3dm (an embedded glb placed once per instance: POSITION or POSITION_QUANTIZED, RTC_CENTER,
// NORMAL_UP/RIGHT or their OCT32P forms or EAST_NORTH_UP, SCALE, SCALE_NON_UNIFORM; one building an
// instance, named by BATCH_ID in the batch table), cmpt (its inner tiles), glb/glTF (CESIUM_RTC,
// EXT_mesh_features, EXT_structural_metadata), external tilesets (a content .json) and 1.1's multiple contents. Each content's glTF is read by the glTF
// reader (gltf.h): y-up to z-up, then RTC centre, then the tile transform: ECEF (EPSG:4978).
//
// Levels of detail: by default the finest level: a tile's content is taken when the tile has no
// children or refines by ADD (its children add to it); under REPLACE a parent's content is replaced by
// its children's. With `geometric_error` >= 0 the walk stops at the first tile whose geometricError is at
// most that many metres (its content taken, its children not visited). No building is taken twice.
//
// Untrusted input: a uri that names the network (http:, https:, any scheme) is never fetched, one that
// leaves the root tileset's folder (.., an absolute path, a symbolic link out) is never read, external
// tilesets that include themselves are cut, transforms that are not finite or not a placement on the
// Earth are refused, and every header length of b3dm/cmpt is checked against the bytes there are: each
// is a Problem naming the tile, and the other tiles are read; so are subtree files whose bitstreams are
// shorter than their levels need. Implicit tiling (QUADTREE, OCTREE; binary or JSON subtrees): its
// available tiles are chosen as explicit ones are, the geometric error halved at each level. Not read (a
// Problem says so): pnts (points), an i3dm whose glTF is given by uri.
#include <groundplan/gis/gltf.h>
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::gis {

struct Tiles3dOptions {
  GltfOptions gltf;             // each content's glTF; its id_field names features (batch table, property table)
  double geometric_error = -1;  // < 0: the finest level; else stop refining at tiles of at most this error (metres)
  int max_depth = 64;           // tiles nested deeper, and external tilesets deeper, are not read
  std::size_t max_tiles = 10'000'000;
  std::uint64_t max_json_bytes = std::uint64_t{256} << 20;  // one tileset.json
};

struct Tiles3dInfo {
  std::string version;          // asset.version of the root tileset
  std::size_t tiles = 0;        // tiles visited
  std::size_t contents = 0;     // contents read (a cmpt counts once per inner tile)
  std::size_t skipped_by_level = 0;  // contents left out by the level-of-detail choice
  std::size_t coarser_copies_left_out = 0;  // buildings left out because a tile below gave them (a finer level)
  std::size_t external_tilesets = 0;
  std::string georeference;     // what the contents' glTF said last (GltfInfo::georeference)
  bool by_feature = false;      // some content split its buildings by feature id
};

/// Reads a tileset.json, or one content file (.b3dm, .i3dm, .cmpt placed as the content of a tile with no
/// transform). Meshes go to `on_mesh` as the glTF reader gives them (GltfFrame::Ecef when placed on the
/// Earth), on the calling thread, content after content, the deepest tiles first (a building id that a tile
/// and a tile below it both hold is read once, from the tile below; the coarser copy is a NOTE problem).
/// The tree is walked first (its JSON only), then the contents chosen are read, parsed and decoded side by side on the current TBB
/// arena, at most two a thread in flight. `progress` (may be empty) is told after each content.
/// Throws InputError naming the file when the root cannot be read at all.
void read_3d_tiles(const std::string& path, const Tiles3dOptions& options, const GltfMeshCallback& on_mesh,
                   std::vector<Problem>& problems, Tiles3dInfo& info,
                   const std::function<void(std::size_t done, std::size_t total)>& progress = {});

/// True when `head` (the first bytes of a file) is a 3D Tiles tileset: JSON with "asset" and "root".
bool looks_like_tileset(std::string_view head);

}  // namespace groundplan::gis

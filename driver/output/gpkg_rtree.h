// SPDX-License-Identifier: MIT
#pragma once
// The GeoPackage spatial index (the "gpkg_rtree_index" extension), built in one pass after the layers
// are written (issue 14).
//
// GDAL 3.6 builds it when a layer is closed, one R*-tree insertion per feature through SQLite's rtree
// module: about half of the time of writing a GeoPackage, and more than linear in the features
// (121,856 plans: ~0.25 s of 0.5 s on the 2-core VM; 609k plans: most of 13 s). GDAL >= 3.7 builds it
// in a background thread and copies it; on 3.6 the CLI writes its layers with SPATIAL_INDEX=NO and then
// calls build_gpkg_rtrees, which packs the tree bottom up (sort-tile-recursive) and writes SQLite's own
// storage of it (the rtree module's _node, _rowid and _parent tables) in one transaction, then the
// spec's triggers and extension row, as GDAL writes them. What a reader sees is what GDAL's index
// gives: the same entries (boxes rounded outwards to float as SQLite rounds them), the same schema,
// triggers that keep it up to date; only the tree's shape differs (packed instead of grown).
#include <string>
#include <vector>

namespace groundplan::output {

/// The feature tables of the GeoPackage at `path` that have a geometry column and no spatial index;
/// empty when the file does not exist or is not a GeoPackage.
std::vector<std::string> gpkg_unindexed_tables(const std::string& path);

struct RtreeBuild {
  std::size_t tables = 0;   // indexes built
  std::size_t entries = 0;  // features indexed (non-empty geometries)
  bool by_gdal = false;     // packing failed (error says why) and GDAL's CreateSpatialIndex built them instead
  double read_s = 0, write_s = 0, commit_s = 0;  // reading the boxes, packing and writing the tree, committing
  std::string error;        // non-empty: what failed (that table's transaction was rolled back)
};

/// Builds the spatial index of every table that has none (the CLI calls it on a GeoPackage it has just
/// created), reading the geometries on `threads` threads. Stops at the first failure.
RtreeBuild build_gpkg_rtrees(const std::string& path, int threads);

/// What the CLI calls after writing a new GeoPackage: build_gpkg_rtrees for every table without an index,
/// and where that fails, GDAL's own CreateSpatialIndex for the tables still without one, so that the file
/// never lacks the index a GDAL user expects. `packed = false` goes straight to GDAL's way. False when a
/// table is left without an index.
bool index_new_gpkg(const std::string& path, int threads, RtreeBuild& built, bool packed = true);

}  // namespace groundplan::output

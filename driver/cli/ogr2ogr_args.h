// SPDX-License-Identifier: MIT
#pragma once
// ogr2ogr's syntax as the CLI takes it: the options GDAL's ogr2ogr parser gets, the destination, the source and the
// layer names told apart (split_ogr2ogr_args), and what the CLI reads from them about the output.
#include <string>
#include <vector>

namespace groundplan::cli {

struct Ogr2ogrArgs {
  std::vector<std::string> options;  // everything but the two datasource names
  std::vector<std::string> layers;   // layer names given after the source
  std::string dst, src;
  bool progress = false;
  bool quiet = false;
  bool layer_named = false;
  std::string format;
};

/// Tells the destination, the source and the layer names from ogr2ogr's options (and their values); throws
/// InvalidArgument when an option lacks its values or the two datasources are not there.
Ogr2ogrArgs split_ogr2ogr_args(const std::vector<std::string>& args);

/// -s_srs / -a_srs name the CRS of the source coordinates: ours to apply before the union (the srsName is wrong or
/// missing), so they are taken out of `options` (what goes to GDAL's ogr2ogr, which would otherwise reproject or
/// relabel our output). The last one given wins.
std::string take_source_srs(std::vector<std::string>& options);

std::string lower(std::string s);

/// True when the output goes to DBF files (Shapefile): string fields hold at most 254 characters.
bool writes_dbf(const Ogr2ogrArgs& ogr);

/// True when the CLI builds the GeoPackage's spatial index itself (gpkg_rtree.h): a new local .gpkg written
/// by GDAL < 3.7 (later versions build theirs in a background thread), the user having said nothing of
/// SPATIAL_INDEX (-lco SPATIAL_INDEX=YES asks for GDAL's own) and not adding to an existing file.
bool packs_gpkg_index(const Ogr2ogrArgs& ogr);

/// ogr2ogr's options without the layer names (they come last); the layers written (ground_plans unless named).
std::vector<std::string> option_flags(const Ogr2ogrArgs& ogr);
std::vector<std::string> written_layers(const Ogr2ogrArgs& ogr);

}  // namespace groundplan::cli

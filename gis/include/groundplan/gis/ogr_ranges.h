// SPDX-License-Identifier: MIT
#pragma once
// One OGR source read on many cores (issue 22): each selected layer is cut into feature ranges; each
// range is read through a dataset handle of its own (a GDALDataset is not thread-safe), and the
// pipeline merges the ranges in feature order, so that the plans, footprints and problems are byte for
// byte those of read_ogr reading the source alone on one thread.
//
// How a layer is cut:
//   - OLCFastSetNextByIndex (Shapefile, GeoJSON ...): ranges of feature indexes, SetNextByIndex(begin)
//     then end - begin features;
//   - a GeoPackage table (FID = SQLite rowid, read in rowid order): ranges of FIDs, an attribute
//     filter "fid >= a AND fid < b" on each handle;
//   - anything else (FlatGeobuf, OSM, CSV, a connection ...), --input-sql, --input-where and
//     --group-by (a building's features may be anywhere in the layer): the source is read whole, and
//     OgrRangePlan::why_not says why (--stats "reading" "read_whole").
// Each range records where it began and ended (OgrRangeWatch); check_ogr_ranges says whether the ranges
// together are exactly the whole layer's reading (a deleted shapefile record, a count that lied, a GDAL
// message at a range's edge make them not), and the caller then reads the source whole. Either way the
// result is read_ogr's.
#include <groundplan/gis/ogr_input.h>

#include <cstdint>
#include <string>
#include <vector>

namespace groundplan::gis {

struct OgrRange {
  std::size_t layer = 0;  // index among the selected layers
  bool by_fid = false;    // [begin, end) are FIDs (GeoPackage), else feature indexes
  std::int64_t begin = 0, end = 0;
};

struct OgrRangePlan {
  std::vector<OgrRange> ranges;      // in feature order; fewer than two: read whole
  std::string why_not;               // non-empty: the source is read whole, and this says why (ranges empty)
  std::vector<Problem> head;         // what opening the source says (notes), said once before its features
  std::string source_srs;            // OgrInfo::source_srs and east_north of the source
  bool east_north = true;
  std::vector<std::int64_t> layer_features;  // features of each selected layer (GDAL's fast count)
};

/// What reading one range met: checked against the plan and the neighbouring ranges.
struct OgrRangeWatch {
  std::int64_t features = 0;      // features read
  std::int64_t first_fid = -1;    // the first one's FID (-1: none read)
  std::int64_t next_fid = -1;     // index ranges: the FID of the feature after the range (-1: the layer's end)
};

/// Cuts the selected layers of `path` into ranges of about `range_features` features (0: about four
/// ranges for each of `threads` threads, at least 20000 features each). Throws InputError when the source
/// cannot be opened (the whole-file reading then says so, as a problem of the file).
OgrRangePlan plan_ogr_ranges(const std::string& path, const OgrInputOptions& options, std::int64_t range_features,
                             std::size_t threads);

/// Reads range `k` of `plan` through a dataset handle of its own, as read_ogr reads those features.
/// Throws InputError when the range cannot be read as part of the whole (a GDAL error or warning that
/// is not one feature's): the caller then reads the source whole.
void read_ogr_range(const std::string& path, const OgrInputOptions& options, const OgrRangePlan& plan, std::size_t k,
                    const std::function<void(Mesh&&)>& on_mesh, std::vector<Problem>& problems, OgrRangeWatch& watch);

/// Empty when the ranges read are together the whole reading of every layer; else why not.
std::string check_ogr_ranges(const OgrRangePlan& plan, const std::vector<OgrRangeWatch>& watches);

}  // namespace groundplan::gis

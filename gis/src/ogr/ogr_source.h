// SPDX-License-Identifier: MIT
#pragma once
// What reading an OGR source whole (ogr_reader.cpp) and reading it in feature ranges side by side
// (ogr_ranges.cpp) share: the source opened with its layers chosen and its CRS fixed, and the turning of
// one feature into a mesh or a Problem. Internal to gis/src/ogr.
#include <groundplan/gis/ogr_input.h>

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace groundplan::gis::ogr_detail {

/// GDAL's errors while this object lives, on this thread only (GDAL's handler stack is per thread):
/// they become Problems instead of lines on stderr.
class ErrorCollector {
 public:
  ErrorCollector();
  ~ErrorCollector();
  ErrorCollector(const ErrorCollector&) = delete;
  ErrorCollector& operator=(const ErrorCollector&) = delete;

  /// Messages since the last take(), joined; empty when none.
  std::string take();
  bool failure() const { return failure_; }

 private:
  static void CPL_STDCALL handler(CPLErr cls, CPLErrorNum, const char* msg);
  std::vector<std::string> messages_;
  std::size_t dropped_ = 0;
  bool failure_ = false;
};

struct DatasetCloser {
  void operator()(GDALDataset* ds) const { GDALClose(GDALDataset::ToHandle(ds)); }
};

struct LayerPlan {
  OGRLayer* layer = nullptr;
  std::string name;
  int id_index = -1;     // --id-field, -1 = the FID
  int group_index = -1;  // --group-by, -1 = none
  int geom_index = 0;    // --input-geom-field, else the first geometry field
  std::unique_ptr<OGRCoordinateTransformation> to_source;  // into the file's source CRS; null = none needed
  bool no_crs = false;   // the file has a CRS and this layer has none
};

/// One OGR source opened, its layers chosen (an SQL result, the named ones, or all), its attribute
/// filter set and its source CRS fixed. Members in this order: GDAL's messages are collected from the
/// opening on, until the dataset is closed.
struct Source {
  ErrorCollector errors;
  std::unique_ptr<GDALDataset, DatasetCloser> ds;
  OGRLayer* sql_layer = nullptr;
  std::vector<LayerPlan> plans;
  Source() = default;
  Source(const Source&) = delete;
  Source& operator=(const Source&) = delete;
  ~Source() {
    if (sql_layer) ds->ReleaseResultSet(sql_layer);
  }
};

/// Opens `path` into `src`. Sets info.driver, layers, source_srs, east_north; notes (a missing field in
/// some layers, ignored geometry fields, GDAL's words while opening) go to `problems`. Throws InputError.
void open_source(const std::string& path, const OgrInputOptions& options, Source& src, std::vector<Problem>& problems,
                 OgrInfo& info);

/// Features into meshes (or Problems), one after the other, as read_ogr documents them.
class FeatureReader {
 public:
  FeatureReader(const std::string& path, const OgrInputOptions& options, Source& src,
                const std::function<void(Mesh&&)>& on_mesh, std::vector<Problem>& problems, OgrInfo& info)
      : path_(path), options_(options), src_(src), on_mesh_(on_mesh), problems_(problems), info_(info),
        prefix_layer_(src.plans.size() > 1) {}
  void read(LayerPlan& p, OGRFeature& feature);
  /// After a layer's last feature: a NOTE for GDAL's warnings, UNREADABLE_FEATURES when a GDAL failure
  /// ended it.
  void layer_stopped(const LayerPlan& p);
  /// --group-by: the buildings, in the order their first feature came.
  void deliver_groups();

 private:
  const std::string& path_;
  const OgrInputOptions& options_;
  Source& src_;
  const std::function<void(Mesh&&)>& on_mesh_;
  std::vector<Problem>& problems_;
  OgrInfo& info_;
  bool prefix_layer_;
  std::size_t layer_features_ = 0;  // features of the layer being read, so far
  // --group-by: one mesh per value, delivered at the end in first-seen order (memory: the file's meshes).
  std::vector<Mesh> groups_;
  std::unordered_map<std::string, std::size_t> group_of_;
};

}  // namespace groundplan::gis::ogr_detail

// SPDX-License-Identifier: MIT
#pragma once
// OGR side of groundplan: a read-only dataset whose layers are the pipeline's result
// (ground_plans, footprints, problems, plan_members). The result is computed when the first dataset of an
// input is opened and shared by later opens (result_cache.h).
#include <groundplan/gis/pipeline.h>
#include <groundplan/gis/tiled.h>

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <functional>
#include <memory>
#include <vector>

namespace groundplan::driver {

/// A layer whose features are made from the pipeline's result when they are read, in batches built on
/// all cores (the next batch while the writer takes the current one): nothing is built for a layer that
/// is not read, and GetNextFeature hands features over without copying them. Filters and counts behave
/// as OGR users expect.
class OGRGroundPlanLayer final : public OGRLayer {
 public:
  /// Makes the feature of index i with `defn` (FID i + 1 unless the maker sets one: a rank writing its share of
  /// a dataset numbers its features as the whole dataset does); called from several threads at once.
  using Maker = std::function<OGRFeature*(OGRFeatureDefn* defn, std::size_t i)>;
  using Extent = std::function<OGREnvelope()>;
  /// `threads`: cores that build batches (0 = all).
  OGRGroundPlanLayer(const char* name, OGRwkbGeometryType geom_type, const OGRSpatialReference* srs,
                     std::size_t count, Maker make, Extent extent = {}, int threads = 0);
  ~OGRGroundPlanLayer() override;

  OGRFeatureDefn* defn() { return defn_; }

  /// Serves only the features of index [first, last) (FIDs first + 1 .. last), e.g. one of several writers'
  /// share of a layer (the CLI's GeoPackage written in slices, cli/gpkg_slices.h). Counts follow the range.
  void restrict_to(std::size_t first, std::size_t last);

  void ResetReading() override;
  OGRFeature* GetNextFeature() override;
  OGRFeature* GetFeature(GIntBig fid) override;
  GIntBig GetFeatureCount(int force) override;
  OGRErr GetExtent(OGREnvelope* extent, int force) override;
  OGRErr GetExtent(int geom_field, OGREnvelope* extent, int force) override;
  OGRFeatureDefn* GetLayerDefn() override { return defn_; }
  int TestCapability(const char* cap) override;

 private:
  using Batch = std::vector<std::unique_ptr<OGRFeature>>;
  bool passes_filters(OGRFeature* f);
  void build(Batch& batch, std::size_t first);  // features [first, first + kBatch) on all cores
  void wait_prefetch();
  void take_batch(std::size_t first);           // the batch that starts at `first`; then prefetches the next

  OGRFeatureDefn* defn_;
  std::size_t begin_ = 0, count_;  // the features served: [begin_, count_)
  Maker make_;
  Extent extent_fn_;
  OGREnvelope extent_;
  bool extent_done_ = false;
  Batch batch_, next_batch_;
  std::size_t batch_first_ = 0, batch_pos_ = 0, next_first_ = 0;
  bool prefetching_ = false;
  tbb::task_arena arena_;
  std::unique_ptr<tbb::task_group> prefetch_ = std::make_unique<tbb::task_group>();  // a member task_group would make the destructor throwing
};

class OGRGroundPlanDataSource final : public GDALDataset {
 public:
  /// Builds the layers from a pipeline result (the CLI calls this after running the pipeline itself).
  /// `max_id_list_chars` > 0 cuts building_ids to that many characters at a comma, ending in
  /// "...(+N)" so the cut is visible (DBF fields hold 254); the full lists are always in plan_members.
  /// It also names fields within DBF's 10 characters: building_ids -> bldg_ids, source_file -> src_file.
  /// `threads`: cores that build the features (0 = all).
  OGRGroundPlanDataSource(const std::string& description, std::shared_ptr<const gis::PipelineResult> result,
                          std::size_t max_id_list_chars = 0, int threads = 0);

  /// The layers of a tiled run (issue 15, gis/tiled.h): ground_plans, problems and plan_members, each plan
  /// read back from the run's temporary file when the writer asks for it. There is no footprints layer: the
  /// tiled run keeps no footprints.
  OGRGroundPlanDataSource(const std::string& description, std::shared_ptr<const gis::TiledResult> tiled,
                          std::size_t max_id_list_chars = 0, int threads = 0);

  /// Plans whose building_ids were cut (see max_id_list_chars); a tiled run's are counted as they are written.
  std::size_t id_lists_cut() const;

  /// The layer called `name`, or null.
  OGRGroundPlanLayer* layer(const char* name);

  int GetLayerCount() override { return static_cast<int>(layers_.size()); }
  OGRLayer* GetLayer(int i) override;
  int TestCapability(const char*) override { return FALSE; }

  /// GDAL's Identify/Open for the GROUNDPLAN: prefix.
  static int Identify(GDALOpenInfo* info);
  static GDALDataset* Open(GDALOpenInfo* info);

 private:
  // Declared before the layers, so destroyed after them: their features' definitions hold srs_, and their
  // makers (and a batch still being built when the writer stops early, e.g. ogr2ogr -limit) read the result.
  std::shared_ptr<const gis::PipelineResult> result_;
  std::shared_ptr<const gis::TiledResult> tiled_;
  std::shared_ptr<std::vector<std::uint8_t>> cut_flags_;  // tiled: plan i's id list was cut
  std::vector<GIntBig> plan_of_;  // the plan (gp_id) that holds each footprint; 0: none
  OGRSpatialReference srs_;
  std::size_t id_lists_cut_ = 0;
  std::vector<std::unique_ptr<OGRGroundPlanLayer>> layers_;
};

/// Registers the driver with GDAL (idempotent). The plugin's RegisterOGRGroundPlan calls it.
void register_driver();

}  // namespace groundplan::driver

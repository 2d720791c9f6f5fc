// SPDX-License-Identifier: MIT
#pragma once
// OGR side of groundplan: a read-only dataset whose layers are the pipeline's result
// (ground_plans, footprints, problems). The pipeline runs once, when the dataset is opened.
#include <groundplan/gis/pipeline.h>

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <memory>
#include <vector>

namespace groundplan::driver {

/// A layer over features built once; filters and counts behave as OGR users expect.
class OGRGroundPlanLayer final : public OGRLayer {
 public:
  OGRGroundPlanLayer(const char* name, OGRwkbGeometryType geom_type, const OGRSpatialReference* srs);
  ~OGRGroundPlanLayer() override;

  OGRFeatureDefn* defn() { return defn_; }
  /// Takes ownership; sets the FID to its position + 1.
  void add(std::unique_ptr<OGRFeature> feature);

  void ResetReading() override { next_ = 0; }
  OGRFeature* GetNextFeature() override;
  OGRFeature* GetFeature(GIntBig fid) override;
  GIntBig GetFeatureCount(int force) override;
  OGRErr GetExtent(OGREnvelope* extent, int force) override;
  OGRErr GetExtent(int geom_field, OGREnvelope* extent, int force) override;
  OGRFeatureDefn* GetLayerDefn() override { return defn_; }
  int TestCapability(const char* cap) override;

 private:
  bool passes_filters(OGRFeature* f);
  OGRFeatureDefn* defn_;
  std::vector<std::unique_ptr<OGRFeature>> features_;
  std::size_t next_ = 0;
  OGREnvelope extent_;
};

class OGRGroundPlanDataSource final : public GDALDataset {
 public:
  /// Builds the layers from a pipeline result (the CLI calls this after running the pipeline itself).
  /// `max_id_list_chars` > 0 cuts building_ids to that many characters at a comma, ending in
  /// "...(+N)" so the cut is visible (DBF fields hold 254); the full lists are always in plan_members.
  /// It also names fields within DBF's 10 characters: building_ids -> bldg_ids, source_file -> src_file.
  OGRGroundPlanDataSource(const std::string& description, const gis::PipelineResult& result,
                          std::size_t max_id_list_chars = 0);

  /// Plans whose building_ids were cut (see max_id_list_chars).
  std::size_t id_lists_cut() const { return id_lists_cut_; }

  int GetLayerCount() override { return static_cast<int>(layers_.size()); }
  OGRLayer* GetLayer(int i) override;
  int TestCapability(const char*) override { return FALSE; }

  /// GDAL's Identify/Open for the GROUNDPLAN: prefix.
  static int Identify(GDALOpenInfo* info);
  static GDALDataset* Open(GDALOpenInfo* info);

 private:
  std::vector<std::unique_ptr<OGRGroundPlanLayer>> layers_;
  OGRSpatialReference srs_;
  std::size_t id_lists_cut_ = 0;
};

/// Registers the driver with GDAL (idempotent). The plugin's RegisterOGRGroundPlan calls it.
void register_driver();

}  // namespace groundplan::driver

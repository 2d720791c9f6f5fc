// SPDX-License-Identifier: MIT
// The fields of the ground_plans and plan_members layers and the layers' SRS, one definition for every source of
// plans (a PipelineResult, a TiledResult, the plans streamed while the union goes on) and so for every writer.
#include "ogr_features.h"

namespace groundplan::driver::detail {

const OGRSpatialReference* layer_srs(const std::string& crs_wkt, OGRSpatialReference& srs) {
  if (crs_wkt.empty() || srs.importFromWkt(crs_wkt.c_str()) != OGRERR_NONE) {
    srs.Clear();
    // GDAL's GeoPackage driver writes this name as the specification's srs_id -1; other formats get a local CRS.
    srs.SetLocalCS("Undefined cartesian SRS");
  }
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return &srs;
}

void PlanIds::add(const Footprint& member) { add(member.source_id, building_id_of(member)); }

void PlanIds::add(const std::string& source_id, const std::string& building_id) {
  if (n_members_++) members_ += ',';
  members_ += source_id;
  if (!seen_.insert(building_id).second) return;
  if (seen_.size() > 1) buildings_ += ',';
  buildings_ += building_id;
}

void add_plan_fields(OGRFeatureDefn* defn, bool dbf) {
  // DBF field names hold 10 characters: say what GDAL would otherwise launder with a warning.
  add_field(defn, "gp_id", OFTInteger64);
  add_field(defn, "n_parts", OFTInteger);
  add_field(defn, "area_m2", OFTReal);
  add_field(defn, "min_z", OFTReal);
  add_field(defn, "max_z", OFTReal);
  add_field(defn, dbf ? "bldg_ids" : "building_ids", OFTString);
  add_field(defn, "buildings", OFTString);
}

void set_plan_fields(OGRFeature* f, GIntBig gp_id, std::size_t n_parts, double area_m2, bool has_z, double min_z,
                     double max_z, const PlanIds& ids, std::size_t max_id_list_chars) {
  f->SetField(0, gp_id);
  f->SetField(1, static_cast<int>(n_parts));
  f->SetField(2, area_m2);
  if (has_z) {
    f->SetField(3, min_z);
    f->SetField(4, max_z);
  }
  f->SetField(5, cut_id_list(ids.members(), ids.member_count(), max_id_list_chars).c_str());
  f->SetField(6, cut_id_list(ids.buildings(), ids.building_count(), max_id_list_chars).c_str());
}

void add_member_fields(OGRFeatureDefn* defn, bool dbf) {
  add_field(defn, "gp_id", OFTInteger64);
  add_field(defn, "fp_id", OFTInteger64);
  add_field(defn, "source_id", OFTString);
  add_field(defn, dbf ? "bldg_id" : "building_id", OFTString);
}

void set_member_fields(OGRFeature* f, GIntBig gp_id, GIntBig fp_id, const std::string& source_id,
                       const std::string& building_id) {
  f->SetField(0, gp_id);
  f->SetField(1, fp_id);
  f->SetField(2, source_id.c_str());
  f->SetField(3, building_id.c_str());
}

}  // namespace groundplan::driver::detail

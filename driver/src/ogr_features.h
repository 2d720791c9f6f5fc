// SPDX-License-Identifier: MIT
#pragma once
// Feature pieces shared by the dataset's two sources (a PipelineResult, a TiledResult).
#include <groundplan/types.h>

#include <ogrsf_frmts.h>

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace groundplan::driver {
class OGRGroundPlanLayer;
}

namespace groundplan::driver::detail {

/// An OGR polygon (rings closed); empty when the outer ring has fewer than 3 points.
OGRPolygon* to_ogr_polygon(const Polygon& poly);
void add_field(OGRFeatureDefn* defn, const char* name, OGRFieldType type, int width = 0);
/// "a,b,c,d" cut to at most `max` characters at a comma, ending in ",...(+N)" with N ids left out (max 0: whole).
std::string cut_id_list(const std::string& ids, std::size_t count, std::size_t max);
/// The "problems" layer (source_id, file, stage, code, reason) over `problems`, which must outlive it (the
/// dataset holds the result the layer reads).
std::unique_ptr<OGRGroundPlanLayer> problems_layer(const std::vector<Problem>* problems, int threads);

/// The SRS of the layers with geometry: the working CRS (`crs_wkt`, WKT2), or, where the input has none, an
/// undefined Cartesian SRS (LOCAL_CS "Undefined cartesian SRS": GeoPackage srs_id -1), never a geographic one:
/// the coordinates are the source's own, not degrees. Sets `srs` (traditional GIS axis order) and returns it.
const OGRSpatialReference* layer_srs(const std::string& crs_wkt, OGRSpatialReference& srs);

/// The ids one ground_plans row lists: its members' own (building_ids) and their Buildings' (buildings: each once,
/// in member order; the Building's id where a member is a BuildingPart, else the member's own id). The ids added
/// must outlive it.
class PlanIds {
 public:
  void add(const Footprint& member);
  void add(const std::string& source_id, const std::string& building_id);
  const std::string& members() const { return members_; }
  const std::string& buildings() const { return buildings_; }
  std::size_t member_count() const { return n_members_; }
  std::size_t building_count() const { return seen_.size(); }
  /// True when either list would be cut at `max` characters (max 0: never).
  bool cut(std::size_t max) const { return max && (members_.size() > max || buildings_.size() > max); }

 private:
  std::string members_, buildings_;
  std::size_t n_members_ = 0;
  std::unordered_set<std::string_view> seen_;  // the Buildings listed
};

/// The ground_plans layer's fields: gp_id, n_parts, area_m2, min_z, max_z, building_ids (bldg_ids), buildings.
void add_plan_fields(OGRFeatureDefn* defn, bool dbf);
/// Sets them on `f`; `has_z` false leaves min_z, max_z unset. The id lists are cut to `max_id_list_chars` (> 0).
void set_plan_fields(OGRFeature* f, GIntBig gp_id, std::size_t n_parts, double area_m2, bool has_z, double min_z,
                     double max_z, const PlanIds& ids, std::size_t max_id_list_chars);
/// The plan_members layer's fields: gp_id, fp_id, source_id (the member), building_id (bldg_id: its Building).
void add_member_fields(OGRFeatureDefn* defn, bool dbf);
void set_member_fields(OGRFeature* f, GIntBig gp_id, GIntBig fp_id, const std::string& source_id,
                       const std::string& building_id);

/// Plan i of a plans layer (it must outlive the layer).
using PlanAt = std::function<const GroundPlan&(std::size_t i)>;
/// The "ground_plans" layer over `count` plans (FID i + 1 for plan_at(i)) whose members index fps[0, n_fps): gp_id,
/// n_parts, area_m2, min_z, max_z, building_ids (bldg_ids) and buildings (both cut to `max_id_list_chars` at a comma,
/// where > 0: a DBF). `extent`: the layer's extent, or empty.
std::unique_ptr<OGRGroundPlanLayer> plans_layer(const OGRSpatialReference* srs, std::size_t count, PlanAt plan_at,
                                                const Footprint* fps, std::size_t n_fps, std::size_t max_id_list_chars,
                                                std::function<OGREnvelope()> extent, int threads);

}  // namespace groundplan::driver::detail

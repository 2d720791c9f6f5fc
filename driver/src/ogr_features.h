// SPDX-License-Identifier: MIT
#pragma once
// Feature pieces shared by the dataset's two sources (a PipelineResult, a TiledResult).
#include <groundplan/types.h>

#include <ogrsf_frmts.h>

#include <functional>
#include <memory>
#include <string>
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

/// Plan i of a plans layer (it must outlive the layer).
using PlanAt = std::function<const GroundPlan&(std::size_t i)>;
/// The "ground_plans" layer over `count` plans (FID i + 1 for plan_at(i)) whose members index fps[0, n_fps): gp_id,
/// n_parts, area_m2, min_z, max_z and building_ids (bldg_ids, cut to `max_id_list_chars` at a comma, where > 0: a
/// DBF). `extent`: the layer's extent, or empty.
std::unique_ptr<OGRGroundPlanLayer> plans_layer(const OGRSpatialReference* srs, std::size_t count, PlanAt plan_at,
                                                const Footprint* fps, std::size_t n_fps, std::size_t max_id_list_chars,
                                                std::function<OGREnvelope()> extent, int threads);

}  // namespace groundplan::driver::detail

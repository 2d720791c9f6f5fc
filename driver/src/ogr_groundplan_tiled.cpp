// SPDX-License-Identifier: MIT
// The dataset's layers over a tiled run (issue 15): plans come from TiledResult::plan(i), read back from the
// run's temporary file by the batch builders (several threads at once), so memory holds one batch of plans.
#include "ogr_features.h"
#include "ogr_groundplan.h"

#include <algorithm>

namespace groundplan::driver {

std::size_t OGRGroundPlanDataSource::id_lists_cut() const {
  if (!cut_flags_) return id_lists_cut_;
  return static_cast<std::size_t>(std::count(cut_flags_->begin(), cut_flags_->end(), std::uint8_t{1}));
}

OGRGroundPlanDataSource::OGRGroundPlanDataSource(const std::string& description,
                                                 std::shared_ptr<const gis::TiledResult> tiled,
                                                 std::size_t max_id_list_chars, int threads)
    : tiled_(std::move(tiled)) {
  SetDescription(description.c_str());
  const gis::TiledResult* res = tiled_.get();
  const OGRSpatialReference* srs = detail::layer_srs(res->crs_wkt, srs_);
  const bool dbf = max_id_list_chars > 0;
  cut_flags_ = std::make_shared<std::vector<std::uint8_t>>(res->plan_count(), 0);
  std::vector<std::uint8_t>* cut = cut_flags_.get();
  auto plans = std::make_unique<OGRGroundPlanLayer>(
      "ground_plans", wkbPolygon, srs, res->plan_count(),
      [res, cut, max_id_list_chars](OGRFeatureDefn* defn, std::size_t i) {
        const gis::StoredPlan sp = res->plan(i);
        auto* f = new OGRFeature(defn);
        detail::PlanIds ids;
        for (std::size_t k = 0; k < sp.member_ids.size(); ++k) ids.add(sp.member_ids[k], sp.member_buildings[k]);
        if (ids.cut(max_id_list_chars)) (*cut)[i] = 1;
        const auto gp_id = static_cast<GIntBig>(res->plan_number(i) + 1);
        f->SetFID(gp_id);
        detail::set_plan_fields(f, gp_id, sp.plan.members.size(), sp.plan.area_m2, !sp.member_ids.empty(), sp.min_z,
                                sp.max_z, ids, max_id_list_chars);
        f->SetGeometryDirectly(detail::to_ogr_polygon(sp.plan.polygon));
        return f;
      },
      [res] {
        OGREnvelope e;
        if (res->extent[0] <= res->extent[2]) {
          e.MinX = res->extent[0];
          e.MinY = res->extent[1];
          e.MaxX = res->extent[2];
          e.MaxY = res->extent[3];
        }
        return e;
      },
      threads);
  detail::add_plan_fields(plans->defn(), dbf);

  auto problems = detail::problems_layer(&res->problems, threads);

  // Row r belongs to the plan i with members_before(i) <= r < members_before(i + 1).
  auto members = std::make_unique<OGRGroundPlanLayer>(
      "plan_members", wkbNone, nullptr, static_cast<std::size_t>(res->members_before(res->plan_count())),
      [res](OGRFeatureDefn* defn, std::size_t r) {
        std::size_t lo = 0, hi = res->plan_count();
        while (hi - lo > 1) {
          const std::size_t mid = lo + (hi - lo) / 2;
          (res->members_before(mid) <= r ? lo : hi) = mid;
        }
        const gis::StoredPlan sp = res->plan(lo);
        const std::size_t k = r - static_cast<std::size_t>(res->members_before(lo));
        auto* f = new OGRFeature(defn);
        f->SetFID(static_cast<GIntBig>(res->row_number(lo) + k) + 1);
        detail::set_member_fields(f, static_cast<GIntBig>(res->plan_number(lo)) + 1,
                                  static_cast<GIntBig>(sp.plan.members[k]) + 1, sp.member_ids[k], sp.member_buildings[k]);
        return f;
      },
      OGRGroundPlanLayer::Extent{}, threads);
  detail::add_member_fields(members->defn(), dbf);

  layers_.push_back(std::move(plans));
  layers_.push_back(std::move(problems));
  layers_.push_back(std::move(members));
}

}  // namespace groundplan::driver

// SPDX-License-Identifier: MIT
// The dataset behind GROUNDPLAN:<path>: takes the pipeline's result on open (computed once per input and
// options in a process: result_cache.h) and serves its layers.
#include "ogr_groundplan.h"
#include "ogr_features.h"
#include "open_options.h"
#include "result_cache.h"

#include <groundplan/error.h>

#include <algorithm>
#include <exception>

namespace groundplan::driver {
namespace {

OGRLinearRing* to_ogr_ring(const Ring& ring) {
  auto* r = new OGRLinearRing();
  r->setNumPoints(static_cast<int>(ring.size() + 1), FALSE);
  for (std::size_t i = 0; i <= ring.size(); ++i) {
    const Point2& p = ring[i % ring.size()];
    r->setPoint(static_cast<int>(i), p.x, p.y);
  }
  return r;
}

}  // namespace

OGRPolygon* detail::to_ogr_polygon(const Polygon& poly) {
  auto* g = new OGRPolygon();
  if (poly.outer.size() < 3) return g;
  g->addRingDirectly(to_ogr_ring(poly.outer));
  for (const Ring& h : poly.holes)
    if (h.size() >= 3) g->addRingDirectly(to_ogr_ring(h));
  return g;
}

void detail::add_field(OGRFeatureDefn* defn, const char* name, OGRFieldType type, int width) {
  OGRFieldDefn f(name, type);
  if (width) f.SetWidth(width);
  defn->AddFieldDefn(&f);
}

/// "a,b,c,d" cut to at most `max` characters at a comma, ending in ",...(+N)" with N ids left out.
std::string detail::cut_id_list(const std::string& ids, std::size_t count, std::size_t max) {
  if (max == 0 || ids.size() <= max) return ids;
  std::size_t kept = 0, end = 0;
  for (std::size_t pos = 0; pos != std::string::npos;) {
    const std::size_t next = ids.find(',', pos);
    const std::size_t stop = next == std::string::npos ? ids.size() : next;
    const std::string tail = ",...(+" + std::to_string(count - kept - 1) + ")";
    if (stop + tail.size() > max) break;
    end = stop;
    ++kept;
    pos = next == std::string::npos ? next : next + 1;
  }
  return ids.substr(0, end) + (kept ? "," : "") + "...(+" + std::to_string(count - kept) + ")";
}

std::unique_ptr<OGRGroundPlanLayer> detail::problems_layer(const std::vector<Problem>* problems, int threads) {
  auto layer = std::make_unique<OGRGroundPlanLayer>(
      "problems", wkbNone, nullptr, problems->size(),
      [problems](OGRFeatureDefn* defn, std::size_t i) {
        const Problem& p = (*problems)[i];
        auto* f = new OGRFeature(defn);
        f->SetField(0, p.source_id.c_str());
        f->SetField(1, p.file.c_str());
        f->SetField(2, p.stage.c_str());
        f->SetField(3, p.code.c_str());
        f->SetField(4, p.reason.c_str());
        return f;
      },
      OGRGroundPlanLayer::Extent{}, threads);
  for (const char* name : {"source_id", "file", "stage", "code", "reason"}) add_field(layer->defn(), name, OFTString);
  return layer;
}

std::unique_ptr<OGRGroundPlanLayer> detail::plans_layer(const OGRSpatialReference* srs, std::size_t count,
                                                       PlanAt plan_at, const Footprint* fps, std::size_t n_fps,
                                                       std::size_t max_id_list_chars, std::function<OGREnvelope()> extent,
                                                       int threads) {
  auto layer = std::make_unique<OGRGroundPlanLayer>(
      "ground_plans", wkbPolygon, srs, count,
      [plan_at = std::move(plan_at), fps, n_fps, max_id_list_chars](OGRFeatureDefn* defn, std::size_t i) {
        const GroundPlan& gp = plan_at(i);
        auto* f = new OGRFeature(defn);
        PlanIds ids;
        double zmin = 0, zmax = 0;
        bool first = true;
        for (std::uint32_t m : gp.members) {
          if (m >= n_fps) continue;
          ids.add(fps[m]);
          zmin = first ? fps[m].min_z : std::min(zmin, fps[m].min_z);
          zmax = first ? fps[m].max_z : std::max(zmax, fps[m].max_z);
          first = false;
        }
        set_plan_fields(f, static_cast<GIntBig>(i + 1), gp.members.size(), gp.area_m2, !first, zmin, zmax, ids,
                        max_id_list_chars);
        f->SetGeometryDirectly(to_ogr_polygon(gp.polygon));
        return f;
      },
      std::move(extent), threads);
  add_plan_fields(layer->defn(), max_id_list_chars > 0);
  return layer;
}

namespace {

/// The envelope of `rings` (outer rings of plans or footprint polygons).
template <class ForEachRing>
OGREnvelope envelope_of(ForEachRing&& for_each_ring) {
  OGREnvelope e;
  for_each_ring([&](const Ring& r) {
    for (const Point2& p : r) e.Merge(p.x, p.y);
  });
  return e;
}

}  // namespace

using detail::add_field;
using detail::cut_id_list;
using detail::to_ogr_polygon;

OGRGroundPlanDataSource::OGRGroundPlanDataSource(const std::string& description,
                                                 std::shared_ptr<const gis::PipelineResult> result,
                                                 std::size_t max_id_list_chars, int threads)
    : result_(std::move(result)) {
  SetDescription(description.c_str());
  const gis::PipelineResult& r = *result_;
  const OGRSpatialReference* srs = detail::layer_srs(r.crs_wkt, srs_);
  const gis::PipelineResult* res = result_.get();  // the layers' makers share it with this dataset
  const auto& fps = r.footprints;

  // Which plan holds each footprint (for the footprints layer's gp_id), and how many id lists a DBF
  // cuts (the CLI says so after writing).
  const bool dbf = max_id_list_chars > 0;
  plan_of_.assign(fps.size(), 0);
  for (std::size_t i = 0; i < r.plans.size(); ++i) {
    detail::PlanIds ids;
    for (std::uint32_t m : r.plans[i].members) {
      if (m >= fps.size()) continue;
      plan_of_[m] = static_cast<GIntBig>(i + 1);
      if (dbf) ids.add(fps[m]);
    }
    id_lists_cut_ += ids.cut(max_id_list_chars);
  }
  const GIntBig* plan_of = plan_of_.data();

  // DBF field names hold 10 characters: say what GDAL would otherwise launder with a warning.
  const char* file_field = dbf ? "src_file" : "source_file";
  auto plans = detail::plans_layer(
      srs, r.plans.size(), [res](std::size_t i) -> const GroundPlan& { return res->plans[i]; }, fps.data(), fps.size(),
      max_id_list_chars,
      [res] {
        return envelope_of([&](auto&& ring) {
          for (const GroundPlan& gp : res->plans) ring(gp.polygon.outer);
        });
      },
      threads);

  auto footprints = std::make_unique<OGRGroundPlanLayer>(
      "footprints", wkbMultiPolygon, srs, fps.size(),
      [res, plan_of](OGRFeatureDefn* defn, std::size_t i) {
        const Footprint& fp = res->footprints[i];
        auto* f = new OGRFeature(defn);
        f->SetField(0, static_cast<GIntBig>(i + 1));
        f->SetField(1, fp.source_id.c_str());
        f->SetField(2, fp.source_file.c_str());
        f->SetField(3, fp.method.c_str());
        if (plan_of[i]) f->SetField(4, plan_of[i]);
        f->SetField(5, fp.min_z);
        f->SetField(6, fp.max_z);
        f->SetField(7, building_id_of(fp).c_str());
        auto* mp = new OGRMultiPolygon();
        for (const Polygon& p : fp.polygons) mp->addGeometryDirectly(to_ogr_polygon(p));
        f->SetGeometryDirectly(mp);
        return f;
      },
      [res] {
        return envelope_of([&](auto&& ring) {
          for (const Footprint& fp : res->footprints)
            for (const Polygon& p : fp.polygons) ring(p.outer);
        });
      },
      threads);
  add_field(footprints->defn(), "fp_id", OFTInteger64);
  add_field(footprints->defn(), "source_id", OFTString);
  add_field(footprints->defn(), file_field, OFTString);
  add_field(footprints->defn(), "method", OFTString);
  add_field(footprints->defn(), "gp_id", OFTInteger64);
  add_field(footprints->defn(), "min_z", OFTReal);
  add_field(footprints->defn(), "max_z", OFTReal);
  add_field(footprints->defn(), dbf ? "bldg_id" : "building_id", OFTString);

  auto problems = detail::problems_layer(&res->problems, threads);

  // One row per (plan, member): the full lists in a form every format holds.
  struct Member {
    std::uint32_t plan, footprint;
  };
  auto rows = std::make_shared<std::vector<Member>>();
  for (std::size_t i = 0; i < r.plans.size(); ++i)
    for (std::uint32_t m : r.plans[i].members)
      if (m < fps.size()) rows->push_back({static_cast<std::uint32_t>(i), m});
  auto members = std::make_unique<OGRGroundPlanLayer>(
      "plan_members", wkbNone, nullptr, rows->size(),
      [res, rows](OGRFeatureDefn* defn, std::size_t i) {
        const Member& m = (*rows)[i];
        auto* f = new OGRFeature(defn);
        const Footprint& fp = res->footprints[m.footprint];
        detail::set_member_fields(f, static_cast<GIntBig>(m.plan) + 1, static_cast<GIntBig>(m.footprint) + 1,
                                  fp.source_id, building_id_of(fp));
        return f;
      },
      OGRGroundPlanLayer::Extent{}, threads);
  detail::add_member_fields(members->defn(), dbf);

  layers_.push_back(std::move(plans));
  layers_.push_back(std::move(footprints));
  layers_.push_back(std::move(problems));
  layers_.push_back(std::move(members));
}

OGRLayer* OGRGroundPlanDataSource::GetLayer(int i) {
  if (i < 0 || i >= GetLayerCount()) return nullptr;
  return layers_[static_cast<std::size_t>(i)].get();
}

OGRGroundPlanLayer* OGRGroundPlanDataSource::layer(const char* name) {
  for (auto& l : layers_)
    if (EQUAL(l->GetName(), name)) return l.get();
  return nullptr;
}

int OGRGroundPlanDataSource::Identify(GDALOpenInfo* info) {
  return STARTS_WITH_CI(info->pszFilename, kPrefix) ? TRUE : FALSE;
}

GDALDataset* OGRGroundPlanDataSource::Open(GDALOpenInfo* info) {
  if (!Identify(info)) return nullptr;
  // Update access (QGIS probes it on every layer load) gets the same read-only dataset, quietly: its
  // layers answer no to every write capability and refuse writes, as read-only layers of other drivers do.
  if (info->eAccess == GA_Update) CPLDebug("GroundPlan", "update access asked: the layers stay read-only");
  // Entry point: convert exceptions once, here (STYLE.md §4).
  try {
    const gis::PipelineOptions options = pipeline_options_from(info->pszFilename, info->papszOpenOptions);
    SharedResult result = cached_pipeline_result(result_cache_key(options.inputs, info->papszOpenOptions),
                                                 info->pszFilename, [&] { return gis::run_pipeline(options); });
    return new OGRGroundPlanDataSource(info->pszFilename, std::move(result), 0, options.threads);
  } catch (const std::exception& e) {
    CPLError(CE_Failure, CPLE_AppDefined, "GroundPlan: %s", e.what());
    return nullptr;
  }
}

void register_driver() {
  if (GDALGetDriverByName("GroundPlan") != nullptr) return;
  auto* d = new GDALDriver();
  d->SetDescription("GroundPlan");
  d->SetMetadataItem(GDAL_DCAP_VECTOR, "YES");
  d->SetMetadataItem(GDAL_DMD_LONGNAME, "Ground plans (union of building footprints) from 3D city models");
  d->SetMetadataItem(GDAL_DMD_CONNECTION_PREFIX, kPrefix);
  d->SetMetadataItem(GDAL_DMD_OPENOPTIONLIST, open_option_list_xml());
  d->SetMetadataItem(GDAL_DCAP_VIRTUALIO, "NO");
  d->pfnIdentify = OGRGroundPlanDataSource::Identify;
  d->pfnOpen = OGRGroundPlanDataSource::Open;
  GetGDALDriverManager()->RegisterDriver(d);
}

}  // namespace groundplan::driver

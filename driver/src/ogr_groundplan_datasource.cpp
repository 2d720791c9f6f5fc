// SPDX-License-Identifier: MIT
// The dataset behind GROUNDPLAN:<path>: runs the pipeline once on open and serves three layers.
#include "ogr_groundplan.h"
#include "open_options.h"

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

OGRPolygon* to_ogr_polygon(const Polygon& poly) {
  auto* g = new OGRPolygon();
  if (poly.outer.size() < 3) return g;
  g->addRingDirectly(to_ogr_ring(poly.outer));
  for (const Ring& h : poly.holes)
    if (h.size() >= 3) g->addRingDirectly(to_ogr_ring(h));
  return g;
}

void add_field(OGRFeatureDefn* defn, const char* name, OGRFieldType type, int width = 0) {
  OGRFieldDefn f(name, type);
  if (width) f.SetWidth(width);
  defn->AddFieldDefn(&f);
}

/// "a,b,c,d" cut to at most `max` characters at a comma, ending in ",...(+N)" with N ids left out.
std::string cut_id_list(const std::string& ids, std::size_t count, std::size_t max) {
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

}  // namespace

OGRGroundPlanDataSource::OGRGroundPlanDataSource(const std::string& description, const gis::PipelineResult& result,
                                                 std::size_t max_id_list_chars) {
  SetDescription(description.c_str());
  const OGRSpatialReference* srs = nullptr;
  if (!result.crs_wkt.empty() && srs_.importFromWkt(result.crs_wkt.c_str()) == OGRERR_NONE) {
    srs_.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    srs = &srs_;
  }
  const auto& fps = result.footprints;

  // Which plan holds each footprint (for the footprints layer's gp_id).
  std::vector<GIntBig> plan_of(fps.size(), 0);

  auto plans = std::make_unique<OGRGroundPlanLayer>("ground_plans", wkbPolygon, srs);
  add_field(plans->defn(), "gp_id", OFTInteger64);
  add_field(plans->defn(), "n_parts", OFTInteger);
  add_field(plans->defn(), "area_m2", OFTReal);
  add_field(plans->defn(), "min_z", OFTReal);
  add_field(plans->defn(), "max_z", OFTReal);
  // DBF field names hold 10 characters: say what GDAL would otherwise launder with a warning.
  const bool dbf = max_id_list_chars > 0;
  const char* ids_field = dbf ? "bldg_ids" : "building_ids";
  const char* file_field = dbf ? "src_file" : "source_file";
  add_field(plans->defn(), ids_field, OFTString);
  for (std::size_t i = 0; i < result.plans.size(); ++i) {
    const GroundPlan& gp = result.plans[i];
    auto f = std::make_unique<OGRFeature>(plans->defn());
    std::string ids;
    double zmin = 0, zmax = 0;
    bool first = true;
    for (std::uint32_t m : gp.members) {
      if (m >= fps.size()) continue;
      plan_of[m] = static_cast<GIntBig>(i + 1);
      if (!ids.empty()) ids += ',';
      ids += fps[m].source_id;
      zmin = first ? fps[m].min_z : std::min(zmin, fps[m].min_z);
      zmax = first ? fps[m].max_z : std::max(zmax, fps[m].max_z);
      first = false;
    }
    f->SetField("gp_id", static_cast<GIntBig>(i + 1));
    f->SetField("n_parts", static_cast<int>(gp.members.size()));
    f->SetField("area_m2", gp.area_m2);
    if (!first) {
      f->SetField("min_z", zmin);
      f->SetField("max_z", zmax);
    }
    const std::string shown = cut_id_list(ids, gp.members.size(), max_id_list_chars);
    id_lists_cut_ += shown.size() != ids.size();
    f->SetField(ids_field, shown.c_str());
    f->SetGeometryDirectly(to_ogr_polygon(gp.polygon));
    plans->add(std::move(f));
  }

  auto footprints = std::make_unique<OGRGroundPlanLayer>("footprints", wkbMultiPolygon, srs);
  add_field(footprints->defn(), "fp_id", OFTInteger64);
  add_field(footprints->defn(), "source_id", OFTString);
  add_field(footprints->defn(), file_field, OFTString);
  add_field(footprints->defn(), "method", OFTString);
  add_field(footprints->defn(), "gp_id", OFTInteger64);
  add_field(footprints->defn(), "min_z", OFTReal);
  add_field(footprints->defn(), "max_z", OFTReal);
  for (std::size_t i = 0; i < fps.size(); ++i) {
    auto f = std::make_unique<OGRFeature>(footprints->defn());
    f->SetField("fp_id", static_cast<GIntBig>(i + 1));
    f->SetField("source_id", fps[i].source_id.c_str());
    f->SetField(file_field, fps[i].source_file.c_str());
    f->SetField("method", fps[i].method.c_str());
    if (plan_of[i]) f->SetField("gp_id", plan_of[i]);
    f->SetField("min_z", fps[i].min_z);
    f->SetField("max_z", fps[i].max_z);
    auto* mp = new OGRMultiPolygon();
    for (const Polygon& p : fps[i].polygons) mp->addGeometryDirectly(to_ogr_polygon(p));
    f->SetGeometryDirectly(mp);
    footprints->add(std::move(f));
  }

  // One row per (plan, member): the full lists in a form every format holds.
  auto members = std::make_unique<OGRGroundPlanLayer>("plan_members", wkbNone, nullptr);
  add_field(members->defn(), "gp_id", OFTInteger64);
  add_field(members->defn(), "fp_id", OFTInteger64);
  add_field(members->defn(), "source_id", OFTString);
  for (std::size_t i = 0; i < result.plans.size(); ++i) {
    for (std::uint32_t m : result.plans[i].members) {
      if (m >= fps.size()) continue;
      auto f = std::make_unique<OGRFeature>(members->defn());
      f->SetField("gp_id", static_cast<GIntBig>(i + 1));
      f->SetField("fp_id", static_cast<GIntBig>(m + 1));
      f->SetField("source_id", fps[m].source_id.c_str());
      members->add(std::move(f));
    }
  }

  auto problems = std::make_unique<OGRGroundPlanLayer>("problems", wkbNone, nullptr);
  for (const char* name : {"source_id", "file", "stage", "code", "reason"}) add_field(problems->defn(), name, OFTString);
  for (const Problem& p : result.problems) {
    auto f = std::make_unique<OGRFeature>(problems->defn());
    f->SetField("source_id", p.source_id.c_str());
    f->SetField("file", p.file.c_str());
    f->SetField("stage", p.stage.c_str());
    f->SetField("code", p.code.c_str());
    f->SetField("reason", p.reason.c_str());
    problems->add(std::move(f));
  }

  layers_.push_back(std::move(plans));
  layers_.push_back(std::move(footprints));
  layers_.push_back(std::move(problems));
  layers_.push_back(std::move(members));
}

OGRLayer* OGRGroundPlanDataSource::GetLayer(int i) {
  if (i < 0 || i >= GetLayerCount()) return nullptr;
  return layers_[static_cast<std::size_t>(i)].get();
}

int OGRGroundPlanDataSource::Identify(GDALOpenInfo* info) {
  return STARTS_WITH_CI(info->pszFilename, kPrefix) ? TRUE : FALSE;
}

GDALDataset* OGRGroundPlanDataSource::Open(GDALOpenInfo* info) {
  if (!Identify(info)) return nullptr;
  if (info->eAccess == GA_Update) {
    CPLError(CE_Failure, CPLE_NotSupported, "GroundPlan: the driver is read-only");
    return nullptr;
  }
  // Entry point: convert exceptions once, here (STYLE.md §4).
  try {
    const gis::PipelineOptions options = pipeline_options_from(info->pszFilename, info->papszOpenOptions);
    const gis::PipelineResult result = gis::run_pipeline(options);
    return new OGRGroundPlanDataSource(info->pszFilename, result);
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

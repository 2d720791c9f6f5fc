// SPDX-License-Identifier: MIT
// --preview: a quick look at the result through GDAL's own rasteriser and PNG writer (no other dependency).
#include "preview.h"

#include <groundplan/error.h>

#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>

namespace groundplan::cli {
namespace {

OGRLinearRing* ring_of(const Ring& r) {
  auto* ring = new OGRLinearRing();
  for (const Point2& p : r) ring->addPoint(p.x, p.y);
  if (!r.empty()) ring->addPoint(r.front().x, r.front().y);
  return ring;
}

OGRPolygon* polygon_of(const Polygon& poly) {
  auto* g = new OGRPolygon();
  g->addRingDirectly(ring_of(poly.outer));
  for (const Ring& h : poly.holes) g->addRingDirectly(ring_of(h));
  return g;
}

OGRLineString* line_of(const Ring& r) {
  auto* line = new OGRLineString();
  for (const Point2& p : r) line->addPoint(p.x, p.y);
  if (!r.empty()) line->addPoint(r.front().x, r.front().y);
  return line;
}

/// Burns `geoms` into the three bands with colour `rgb`; takes ownership of the geometries.
void burn(GDALDataset* ds, std::vector<OGRGeometry*>& geoms, const double rgb[3], bool all_touched) {
  if (geoms.empty()) return;
  int bands[3] = {1, 2, 3};
  std::vector<double> values;
  for (std::size_t i = 0; i < geoms.size(); ++i) values.insert(values.end(), rgb, rgb + 3);
  char** options = all_touched ? CSLSetNameValue(nullptr, "ALL_TOUCHED", "TRUE") : nullptr;
  std::vector<OGRGeometryH> handles(geoms.begin(), geoms.end());
  const CPLErr err = GDALRasterizeGeometries(GDALDataset::ToHandle(ds), 3, bands, static_cast<int>(handles.size()),
                                             handles.data(), nullptr, nullptr, values.data(), options, nullptr,
                                             nullptr);
  CSLDestroy(options);
  for (OGRGeometry* g : geoms) delete g;
  geoms.clear();
  if (err != CE_None) throw Error("preview: rasterising failed");
}

}  // namespace

void write_preview_png(const gis::PipelineResult& result, const std::string& path, int max_side_px) {
  OGREnvelope env;
  for (const auto& p : result.plans)
    for (const Point2& q : p.polygon.outer) env.Merge(q.x, q.y);
  for (const auto& f : result.footprints)
    for (const auto& poly : f.polygons)
      for (const Point2& q : poly.outer) env.Merge(q.x, q.y);
  if (!env.IsInit()) throw Error("preview: nothing to draw (no plans)");
  const double w = std::max(env.MaxX - env.MinX, 1e-9), h = std::max(env.MaxY - env.MinY, 1e-9);
  const double margin = 0.02 * std::max(w, h);
  const double px = (std::max(w, h) + 2 * margin) / max_side_px;
  const int width = std::max(1, static_cast<int>(std::ceil((w + 2 * margin) / px)));
  const int height = std::max(1, static_cast<int>(std::ceil((h + 2 * margin) / px)));

  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* png = GetGDALDriverManager()->GetDriverByName("PNG");
  if (!mem || !png) throw Error("preview: GDAL has no MEM or PNG driver");
  std::unique_ptr<GDALDataset> ds(mem->Create("", width, height, 3, GDT_Byte, nullptr));
  double gt[6] = {env.MinX - margin, px, 0, env.MaxY + margin, 0, -px};
  ds->SetGeoTransform(gt);
  for (int b = 1; b <= 3; ++b) ds->GetRasterBand(b)->Fill(255);

  std::vector<OGRGeometry*> geoms;
  for (const auto& p : result.plans) geoms.push_back(polygon_of(p.polygon));
  const double fill[3] = {166, 189, 219};
  burn(ds.get(), geoms, fill, false);

  for (const auto& p : result.plans) {
    geoms.push_back(line_of(p.polygon.outer));
    for (const Ring& r : p.polygon.holes) geoms.push_back(line_of(r));
  }
  const double outline[3] = {8, 48, 107};
  burn(ds.get(), geoms, outline, true);

  // Footprints of buildings with a problem (union stage: they are read but in no plan), in red.
  std::set<std::string> flagged;
  for (const auto& pr : result.problems)
    if (!pr.source_id.empty()) flagged.insert(pr.source_id);
  for (const auto& f : result.footprints)
    if (flagged.count(f.source_id))
      for (const auto& poly : f.polygons) geoms.push_back(line_of(poly.outer));
  const double red[3] = {215, 25, 28};
  burn(ds.get(), geoms, red, true);

  std::unique_ptr<GDALDataset> out(png->CreateCopy(path.c_str(), ds.get(), FALSE, nullptr, nullptr, nullptr));
  if (!out) throw Error("preview: cannot write " + path);
}

}  // namespace groundplan::cli

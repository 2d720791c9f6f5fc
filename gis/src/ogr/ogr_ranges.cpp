// SPDX-License-Identifier: MIT
// One OGR source in feature ranges side by side (issue 22): ogr_ranges.h says how a layer is cut and
// why the ranges read it exactly as the whole reading does.
#include <groundplan/error.h>
#include <groundplan/gis/ogr_ranges.h>

#include "ogr/ogr_source.h"

#include <algorithm>
#include <cstdint>

namespace groundplan::gis {
namespace {

using ogr_detail::LayerPlan;
using ogr_detail::Source;

std::string quoted(const std::string& name) {
  std::string out = "\"";
  for (char c : name) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// A GeoPackage table's [lowest, highest] FID; false when the statement gives none.
bool fid_bounds(GDALDataset& ds, OGRLayer& layer, std::int64_t& lo, std::int64_t& hi) {
  const std::string sql = "SELECT MIN(" + quoted(layer.GetFIDColumn()) + "), MAX(" + quoted(layer.GetFIDColumn()) +
                          ") FROM " + quoted(layer.GetName());
  OGRLayer* r = ds.ExecuteSQL(sql.c_str(), nullptr, "SQLITE");
  if (!r) return false;
  std::unique_ptr<OGRFeature> f(r->GetNextFeature());
  const bool ok = f && f->IsFieldSetAndNotNull(0) && f->IsFieldSetAndNotNull(1);
  if (ok) {
    lo = f->GetFieldAsInteger64(0);
    hi = f->GetFieldAsInteger64(1);
  }
  ds.ReleaseResultSet(r);
  return ok;
}

std::string fid_filter(const OGRLayer& layer, std::int64_t begin, std::int64_t end) {
  const std::string fid = quoted(const_cast<OGRLayer&>(layer).GetFIDColumn());
  return fid + " >= " + std::to_string(begin) + " AND " + fid + " < " + std::to_string(end);
}

}  // namespace

OgrRangePlan plan_ogr_ranges(const std::string& path, const OgrInputOptions& options, std::int64_t range_features,
                             std::size_t threads) {
  OgrRangePlan plan;
  Source src;
  OgrInfo info;
  ogr_detail::open_source(path, options, src, plan.head, info);
  plan.source_srs = info.source_srs;
  plan.east_north = info.east_north;
  auto whole = [&](std::string why) {
    plan.ranges.clear();
    plan.why_not = std::move(why);
    return plan;
  };
  if (!options.sql.empty()) return whole("--input-sql: a statement's result is read in one piece");
  if (!options.where.empty()) return whole("--input-where: a filtered layer has no fast seek to its n-th feature");
  if (!options.group_by.empty())
    return whole("--group-by: a building's features may lie anywhere in the layer, so it is read in one piece");
  if (src.ds->TestCapability(ODsCRandomLayerRead))
    return whole(info.driver + " gives its layers' features interleaved (ODsCRandomLayerRead): read in one piece");
  enum class Cut { ByIndex, ByFid };
  std::vector<Cut> cuts;
  for (std::size_t li = 0; li < src.plans.size(); ++li) {
    OGRLayer& layer = *src.plans[li].layer;
    const std::string named = "layer '" + src.plans[li].name + "' (" + info.driver + ")";
    if (!layer.TestCapability(OLCFastFeatureCount)) return whole(named + " has no fast feature count");
    const std::int64_t n = layer.GetFeatureCount(TRUE);
    if (n < 0) return whole(named + " gives no feature count");
    plan.layer_features.push_back(n);
    if (layer.TestCapability(OLCFastSetNextByIndex))
      cuts.push_back(Cut::ByIndex);
    else if (info.driver == "GPKG" && layer.GetFIDColumn() && *layer.GetFIDColumn())
      cuts.push_back(Cut::ByFid);
    else
      return whole(named + " has no fast seek to its n-th feature (OLCFastSetNextByIndex)");
  }
  if (range_features <= 0) {
    std::int64_t total = 0;
    for (std::int64_t n : plan.layer_features) total += n;
    range_features = std::max<std::int64_t>(20000, total / static_cast<std::int64_t>(4 * std::max<std::size_t>(threads, 1)));
  }
  for (std::size_t li = 0; li < src.plans.size(); ++li) {
    OGRLayer& layer = *src.plans[li].layer;
    const std::int64_t n = plan.layer_features[li];
    const std::int64_t pieces = std::max<std::int64_t>(1, (n + range_features - 1) / range_features);
    if (cuts[li] == Cut::ByIndex) {
      for (std::int64_t k = 0; k < pieces; ++k) plan.ranges.push_back({li, false, n * k / pieces, n * (k + 1) / pieces});
      continue;
    }
    std::int64_t lo = 0, hi = -1;
    if (n > 0 && !fid_bounds(*src.ds, layer, lo, hi))
      return whole("layer '" + src.plans[li].name + "': its FID bounds cannot be read");
    const std::int64_t span = hi - lo + 1;  // FIDs need not be dense: the ranges are cut in FID space
    for (std::int64_t k = 0; k < pieces && n > 0; ++k)
      plan.ranges.push_back({li, true, lo + span * k / pieces, lo + span * (k + 1) / pieces});
  }
  if (const std::string said = src.errors.take(); !said.empty())
    return whole("GDAL said something while the source was planned: " + said);
  return plan;
}

void read_ogr_range(const std::string& path, const OgrInputOptions& options, const OgrRangePlan& plan, std::size_t k,
                    const std::function<void(Mesh&&)>& on_mesh, std::vector<Problem>& problems, OgrRangeWatch& watch) {
  const OgrRange& r = plan.ranges.at(k);
  const std::string where = path + ": feature range " + std::to_string(k + 1) + " of " + std::to_string(plan.ranges.size());
  Source src;
  OgrInfo info;
  std::vector<Problem> head;  // said once, by the plan
  ogr_detail::open_source(path, options, src, head, info);
  if (info.source_srs != plan.source_srs || r.layer >= src.plans.size())
    throw InputError(where + ": the source changed between two openings");
  LayerPlan& p = src.plans[r.layer];
  OGRLayer& layer = *p.layer;
  if (r.by_fid) {
    if (layer.SetAttributeFilter(fid_filter(layer, r.begin, r.end).c_str()) != OGRERR_NONE)
      throw InputError(where + ": the FID filter is refused: " + src.errors.take());
  } else {
    layer.ResetReading();
    if (r.begin > 0 && layer.SetNextByIndex(r.begin) != OGRERR_NONE)
      throw InputError(where + ": cannot seek to feature " + std::to_string(r.begin) + ": " + src.errors.take());
  }
  if (const std::string said = src.errors.take(); !said.empty()) throw InputError(where + ": " + said);
  ogr_detail::FeatureReader reader(path, options, src, on_mesh, problems, info);
  const std::int64_t want = r.by_fid ? INT64_MAX : r.end - r.begin;
  while (watch.features < want) {
    std::unique_ptr<OGRFeature> feature(layer.GetNextFeature());
    if (!feature) break;
    if (watch.features++ == 0) watch.first_fid = feature->GetFID();
    reader.read(p, *feature);
  }
  // What the whole reading would say at this point as a note or a failure (the layer's end) is its own:
  // the ranges do not stand for it.
  if (const std::string said = src.errors.take(); !said.empty()) throw InputError(where + ": " + said);
  if (!r.by_fid) {
    std::unique_ptr<OGRFeature> next(layer.GetNextFeature());
    watch.next_fid = next ? next->GetFID() : -1;
    const std::string said = src.errors.take();
    const bool last = k + 1 == plan.ranges.size() || plan.ranges[k + 1].layer != r.layer;
    if (last && !said.empty()) throw InputError(where + ": at the layer's end: " + said);
  }
}

std::string check_ogr_ranges(const OgrRangePlan& plan, const std::vector<OgrRangeWatch>& watches) {
  std::vector<std::int64_t> read(plan.layer_features.size(), 0);
  for (std::size_t k = 0; k < plan.ranges.size(); ++k) {
    const OgrRange& r = plan.ranges[k];
    const OgrRangeWatch& w = watches.at(k);
    read.at(r.layer) += w.features;
    if (r.by_fid) continue;
    const std::string at = "feature range " + std::to_string(k + 1) + ": ";
    if (w.features != r.end - r.begin)
      return at + std::to_string(w.features) + " features read, " + std::to_string(r.end - r.begin) + " expected";
    const bool last = k + 1 == plan.ranges.size() || plan.ranges[k + 1].layer != r.layer;
    if (last && w.next_fid != -1) return at + "the layer has features after its counted end";
    if (!last && w.next_fid != watches[k + 1].first_fid)
      return at + "does not end where the next range begins (FID " + std::to_string(w.next_fid) + " against " +
             std::to_string(watches[k + 1].first_fid) + ")";
  }
  for (std::size_t li = 0; li < read.size(); ++li)
    if (read[li] != plan.layer_features[li])
      return "layer " + std::to_string(li + 1) + ": the ranges read " + std::to_string(read[li]) + " features, the layer counts " +
             std::to_string(plan.layer_features[li]);
  return {};
}

}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
#include "ogr_groundplan.h"

namespace groundplan::driver {

OGRGroundPlanLayer::OGRGroundPlanLayer(const char* name, OGRwkbGeometryType geom_type, const OGRSpatialReference* srs)
    : defn_(new OGRFeatureDefn(name)) {
  defn_->Reference();
  defn_->SetGeomType(geom_type);
  if (geom_type != wkbNone && srs) defn_->GetGeomFieldDefn(0)->SetSpatialRef(const_cast<OGRSpatialReference*>(srs));  // GDAL 3.6 takes non-const
  SetDescription(name);
}

OGRGroundPlanLayer::~OGRGroundPlanLayer() { defn_->Release(); }

void OGRGroundPlanLayer::add(std::unique_ptr<OGRFeature> feature) {
  feature->SetFID(static_cast<GIntBig>(features_.size()) + 1);
  if (const OGRGeometry* g = feature->GetGeometryRef(); g && !g->IsEmpty()) {
    OGREnvelope e;
    g->getEnvelope(&e);
    extent_.Merge(e);
  }
  features_.push_back(std::move(feature));
}

bool OGRGroundPlanLayer::passes_filters(OGRFeature* f) {
  return (m_poFilterGeom == nullptr || FilterGeometry(f->GetGeometryRef())) &&
         (m_poAttrQuery == nullptr || m_poAttrQuery->Evaluate(f));
}

OGRFeature* OGRGroundPlanLayer::GetNextFeature() {
  while (next_ < features_.size()) {
    OGRFeature* f = features_[next_++].get();
    if (passes_filters(f)) return f->Clone();
  }
  return nullptr;
}

OGRFeature* OGRGroundPlanLayer::GetFeature(GIntBig fid) {
  if (fid < 1 || fid > static_cast<GIntBig>(features_.size())) return nullptr;
  return features_[static_cast<std::size_t>(fid - 1)]->Clone();
}

GIntBig OGRGroundPlanLayer::GetFeatureCount(int force) {
  if (m_poFilterGeom == nullptr && m_poAttrQuery == nullptr) return static_cast<GIntBig>(features_.size());
  return OGRLayer::GetFeatureCount(force);
}

OGRErr OGRGroundPlanLayer::GetExtent(OGREnvelope* extent, int force) {
  if (defn_->GetGeomType() == wkbNone || !extent_.IsInit()) return OGRERR_FAILURE;
  *extent = extent_;
  return OGRERR_NONE;
}

OGRErr OGRGroundPlanLayer::GetExtent(int geom_field, OGREnvelope* extent, int force) {
  if (geom_field != 0) return OGRERR_FAILURE;
  return GetExtent(extent, force);
}

int OGRGroundPlanLayer::TestCapability(const char* cap) {
  if (EQUAL(cap, OLCFastFeatureCount)) return m_poFilterGeom == nullptr && m_poAttrQuery == nullptr;
  if (EQUAL(cap, OLCFastGetExtent) || EQUAL(cap, OLCRandomRead) || EQUAL(cap, OLCStringsAsUTF8)) return TRUE;
  return FALSE;
}

}  // namespace groundplan::driver

// SPDX-License-Identifier: MIT
#include "ogr_groundplan.h"

#include <tbb/parallel_for.h>

#include <algorithm>

namespace groundplan::driver {
namespace {
// Features a batch: large enough that building one on all cores pays, small enough to stay in cache.
constexpr std::size_t kBatch = 4096;
}  // namespace

OGRGroundPlanLayer::OGRGroundPlanLayer(const char* name, OGRwkbGeometryType geom_type, const OGRSpatialReference* srs,
                                       std::size_t count, Maker make, Extent extent, int threads)
    : defn_(new OGRFeatureDefn(name)), count_(count), make_(std::move(make)), extent_fn_(std::move(extent)),
      arena_(threads > 0 ? threads : tbb::task_arena::automatic) {
  defn_->Reference();
  defn_->SetGeomType(geom_type);
  if (geom_type != wkbNone && srs) defn_->GetGeomFieldDefn(0)->SetSpatialRef(const_cast<OGRSpatialReference*>(srs));  // GDAL 3.6 takes non-const
  SetDescription(name);
}

OGRGroundPlanLayer::~OGRGroundPlanLayer() {
  try {
    wait_prefetch();
  } catch (...) {
  }
  batch_.clear();
  next_batch_.clear();
  defn_->Release();
}

void OGRGroundPlanLayer::restrict_to(std::size_t first, std::size_t last) {
  ResetReading();
  next_batch_.clear();
  last = std::min(last, count_);
  begin_ = std::min(first, last);
  count_ = last;
  batch_first_ = begin_;
}

void OGRGroundPlanLayer::build(Batch& batch, std::size_t first) {
  const std::size_t n = std::min(kBatch, count_ - first);
  batch.clear();
  batch.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      batch[i].reset(make_(defn_, first + i));
      if (batch[i]->GetFID() == OGRNullFID) batch[i]->SetFID(static_cast<GIntBig>(first + i) + 1);
    }
  });
}

void OGRGroundPlanLayer::wait_prefetch() {
  if (!prefetching_) return;
  prefetching_ = false;
  arena_.execute([&] { prefetch_->wait(); });
}

void OGRGroundPlanLayer::take_batch(std::size_t first) {
  wait_prefetch();
  if (next_first_ == first && !next_batch_.empty())
    std::swap(batch_, next_batch_);
  else
    arena_.execute([&] { build(batch_, first); });
  batch_first_ = first;
  batch_pos_ = 0;
  const std::size_t after = first + batch_.size();
  if (after < count_) {  // the next batch while the caller writes this one
    next_first_ = after;
    prefetching_ = true;
    arena_.execute([&] { prefetch_->run([this, after] { build(next_batch_, after); }); });
  }
}

void OGRGroundPlanLayer::ResetReading() {
  wait_prefetch();
  batch_.clear();
  batch_first_ = begin_;
  batch_pos_ = 0;
}

bool OGRGroundPlanLayer::passes_filters(OGRFeature* f) {
  return (m_poFilterGeom == nullptr || FilterGeometry(f->GetGeometryRef())) &&
         (m_poAttrQuery == nullptr || m_poAttrQuery->Evaluate(f));
}

OGRFeature* OGRGroundPlanLayer::GetNextFeature() {
  for (;;) {
    if (batch_pos_ >= batch_.size()) {
      const std::size_t first = batch_first_ + batch_.size();
      if (first >= count_) return nullptr;
      take_batch(first);
    }
    std::unique_ptr<OGRFeature> f = std::move(batch_[batch_pos_++]);
    if (passes_filters(f.get())) return f.release();
  }
}

OGRFeature* OGRGroundPlanLayer::GetFeature(GIntBig fid) {
  if (fid <= static_cast<GIntBig>(begin_) || fid > static_cast<GIntBig>(count_)) return nullptr;
  OGRFeature* f = make_(defn_, static_cast<std::size_t>(fid - 1));
  f->SetFID(fid);
  return f;
}

GIntBig OGRGroundPlanLayer::GetFeatureCount(int force) {
  if (m_poFilterGeom == nullptr && m_poAttrQuery == nullptr) return static_cast<GIntBig>(count_ - begin_);
  return OGRLayer::GetFeatureCount(force);
}

OGRErr OGRGroundPlanLayer::GetExtent(OGREnvelope* extent, int force) {
  if (defn_->GetGeomType() == wkbNone || !extent_fn_) return OGRERR_FAILURE;
  if (!extent_done_) {
    extent_ = extent_fn_();
    extent_done_ = true;
  }
  if (!extent_.IsInit()) return OGRERR_FAILURE;
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

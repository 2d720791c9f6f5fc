// SPDX-License-Identifier: MIT
#include "streamed_gpkg.h"

#include "ogr_features.h"
#include "ogr_groundplan.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <memory>

namespace groundplan::output {
namespace {

// Plans a slice at least: below this a slice's own ogr2ogr (a file, its tables) costs more than it saves.
constexpr std::size_t kMinSlicePlans = 4096;
// Slices a writer, about: more than one, so that the appending follows the writers closely.
constexpr std::size_t kSlicesPerWriter = 2;

/// One plans layer over some of the feed's plans, for one writer.
class FeedDataset final : public GDALDataset {
 public:
  explicit FeedDataset(std::unique_ptr<driver::OGRGroundPlanLayer> layer) : layer_(std::move(layer)) {
    SetDescription("groundplan: plans of the union under way");
  }
  int GetLayerCount() override { return 1; }
  OGRLayer* GetLayer(int i) override { return i == 0 ? layer_.get() : nullptr; }
  int TestCapability(const char*) override { return FALSE; }

 private:
  std::unique_ptr<driver::OGRGroundPlanLayer> layer_;
};

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

StreamedGpkg::StreamedGpkg(Setup setup) : setup_(std::move(setup)) {
  table_ = table_name(setup_.write.flags, setup_.write.plans_layer);
  for (const std::string& l : setup_.write.layers)
    if (!EQUAL(l.c_str(), setup_.write.plans_layer.c_str())) slice0_late_ = true;
}

StreamedGpkg::~StreamedGpkg() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!finished_ok_) failed_ = true;
  }
  changed_.notify_all();
  for (std::thread& t : threads_)
    if (t.joinable()) t.join();
  if (engaged_ && !finished_ok_) {
    const std::size_t taken = next_slice_.load() + 1;
    for (std::size_t k = 1; k <= std::max(taken, written_.size()); ++k)
      remove_with_sidecars(slice_path(setup_.write.dst, k, ".gpkg"));
    remove_with_sidecars(setup_.write.dst);
  }
}

PlanFeed* StreamedGpkg::engage(const gis::PipelineResult& read) {
  fps_ = read.footprints.data();
  n_fps_ = read.footprints.size();
  driver::detail::layer_srs(read.crs_wkt, srs_);
  return this;
}

void StreamedGpkg::begin(std::size_t blocks) {
  // The plans are between the blocks (a block of the raster can hold several plans) and the footprints in number:
  // guessed halfway, for the writers gpkg_writers would give and the slices' size.
  const std::size_t guess = (blocks + n_fps_) / 2;
  writers_ = writers_for(guess, setup_.threads, nullptr);
  if (writers_ < 2) return;  // few plans: the caller writes them after the union, as before
  engaged_ = true;
  t_begin_ = now_s();
  by_block_.resize(blocks);
  done_.assign(blocks, 0);
  first_.assign(blocks + 1, 0);
  const std::size_t slices = kSlicesPerWriter * static_cast<std::size_t>(writers_);
  slice_plans_ = std::max(kMinSlicePlans, (guess + slices - 1) / slices);
  for (int w = 0; w < writers_; ++w) threads_.emplace_back([this] { write_slices(); });
  threads_.emplace_back([this] { append_slices(); });
}

void StreamedGpkg::block_done(std::size_t b, const std::vector<GroundPlan>& plans) {
  if (!engaged_) return;
  by_block_[b] = plans;  // this block's entry alone: published by the lock below
  bool crossed = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_[b] = 1;
    const std::size_t before = ready_;
    while (prefix_ < done_.size() && done_[prefix_]) {
      first_[prefix_ + 1] = first_[prefix_] + by_block_[prefix_].size();
      ++prefix_;
    }
    ready_ = first_[prefix_];
    crossed = ready_ / slice_plans_ != before / slice_plans_;
  }
  if (crossed) changed_.notify_all();
}

void StreamedGpkg::end(bool complete) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ended_ = true;
    if (!(complete && prefix_ == done_.size()) && !failed_) {
      failed_ = true;
      error_ = "the union stopped before its last block";
    }
    if (engaged_) slices_total_ = std::max<std::size_t>(1, (ready_ + slice_plans_ - 1) / slice_plans_);
  }
  changed_.notify_all();
}

void StreamedGpkg::fail(std::string why) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!failed_) error_ = std::move(why);
    failed_ = true;
  }
  changed_.notify_all();
}

bool StreamedGpkg::write_one(std::size_t k, std::size_t first, std::size_t last, const SliceSource* whole) {
  GDALDatasetH src = nullptr;
  std::size_t blocks_seen = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    blocks_seen = prefix_;
  }
  if (whole) {
    src = (*whole)(first, last);
  } else {
    const std::vector<std::size_t>* first_of = &first_;
    const std::vector<std::vector<GroundPlan>>* by_block = &by_block_;
    auto layer = driver::detail::plans_layer(
        &srs_, last,
        [first_of, by_block, blocks_seen](std::size_t i) -> const GroundPlan& {
          // The last block of the prefix seen whose first plan is at or before i (empty blocks share a first plan).
          const auto it = std::upper_bound(first_of->begin(), first_of->begin() + static_cast<std::ptrdiff_t>(blocks_seen) + 1, i);
          const std::size_t b = static_cast<std::size_t>(it - first_of->begin()) - 1;
          return (*by_block)[b][i - (*first_of)[b]];
        },
        fps_, n_fps_, setup_.id_chars, {}, 1);
    layer->restrict_to(first, last);
    src = GDALDataset::ToHandle(new FeedDataset(std::move(layer)));
  }
  if (!src) {
    fail("slice " + std::to_string(k) + " of the plans: no dataset to write it from");
    return false;
  }
  std::vector<std::string> args = setup_.write.flags;
  args.push_back("-preserve_fid");  // the source's FIDs are the plans' indices + 1: slices append in any order
  if (k == 0)
    args.insert(args.end(), setup_.write.layers.begin(), setup_.write.layers.end());
  else
    args.push_back(setup_.write.plans_layer);
  int usage = 0;
  const bool ok = setup_.translate(slice_path(setup_.write.dst, k, ".gpkg"), src, args,
                                   whole != nullptr && setup_.write.progress, &usage);
  GDALClose(src);
  if (!ok) {
    fail("writing slice " + std::to_string(k) + " of the plans failed" + (usage ? " (bad ogr2ogr options)" : ""));
    return false;
  }
  if (!whole) {  // the copies of the blocks that lie in this slice alone are no longer needed
    const auto lo = std::lower_bound(first_.begin(), first_.begin() + static_cast<std::ptrdiff_t>(blocks_seen) + 1, first);
    for (auto b = static_cast<std::size_t>(lo - first_.begin()); b < blocks_seen && first_[b + 1] <= last; ++b)
      std::vector<GroundPlan>().swap(by_block_[b]);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (written_.size() <= k) written_.resize(k + 1, 0);
    written_[k] = 1;
  }
  changed_.notify_all();
  return true;
}

void StreamedGpkg::write_slices() {
  for (;;) {
    const std::size_t k = next_slice_.fetch_add(1);
    if (k == 0 && slice0_late_) continue;  // finish() writes it, with the other layers
    const std::size_t first = k * slice_plans_;
    std::size_t last = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return failed_ || ended_ || ready_ >= first + slice_plans_; });
      if (failed_ || (ended_ && k >= slices_total_)) return;
      last = std::min(first + slice_plans_, ready_);
      if (!ended_) ++early_;
    }
    if (!write_one(k, first, last, nullptr)) return;
  }
}

void StreamedGpkg::append_slices() {
  try {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return failed_ || (!written_.empty() && written_[0]); });
      if (failed_) return;
    }
    Appender appender(setup_.write.dst, {table_});
    for (std::size_t k = 1;; ++k) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] {
          return failed_ || (k < written_.size() && written_[k]) || (ended_ && k >= slices_total_);
        });
        if (failed_) return;
        if (!(k < written_.size() && written_[k])) break;  // ended, and k is past the last slice
      }
      const std::string part = slice_path(setup_.write.dst, k, ".gpkg");
      appender.append({part, table_});
      remove_with_sidecars(part);
    }
    appender.finish();
    std::lock_guard<std::mutex> lock(mutex_);
    appended_ = true;
  } catch (const std::exception& e) {
    fail(std::string("appending the slices failed: ") + e.what());
    return;
  }
  changed_.notify_all();
}

SliceOutcome StreamedGpkg::finish(const SliceSource& slice0) {
  SliceOutcome out;
  const double t0 = now_s();
  bool ok = true;
  if (slice0_late_) {
    std::size_t last = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ok = !failed_;
      last = std::min(slice_plans_, ready_);
    }
    if (ok) ok = write_one(0, 0, last, &slice0);
  }
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return failed_ || appended_; });
    ok = !failed_;
    out.error = error_;
  }
  for (std::thread& t : threads_) t.join();
  threads_.clear();
  out.merge_s = now_s() - t0;  // what the write took after the union
  out.slices_s = now_s() - t_begin_;
  if (!ok) return out;
  finished_ok_ = true;
  out.ok = true;
  return out;
}

std::size_t StreamedGpkg::slices() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return finished_ok_ ? slices_total_ : 0;
}

std::size_t StreamedGpkg::slices_before_end() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return early_;
}

}  // namespace groundplan::output

// SPDX-License-Identifier: MIT
#pragma once
// A new GeoPackage written while the union goes on (issue 14: "plans go to the OGR writer while later blocks are
// still being united").
//
// The same file as the slices of gpkg_slices.h give, written earlier: the union tells this feed each block's plans
// as soon as that block is united (ground_plans.h PlanFeed); the blocks are taken in block order, so the plans are
// final from the first one on. The plans layer is cut into slices of a fixed number of plans (set from a guess of their
// number, between the blocks' and the footprints'); writer threads take the slices in order, each as soon as all its
// plans are final, and write it by its own ogr2ogr (the user's options, FIDs kept) into its own file; one more
// thread appends each written slice to the destination, in slice order, while the later ones are still written.
// Slice 0 is the destination: written by a writer like the others when the plans layer is all that is asked for,
// else after the union by the caller (finish), with the other layers, which need the whole result (problems ...).
// What a reader gets is what one writer gives: the same tables, rows, FIDs, extent and count.
#include "gpkg_slices.h"

#include <groundplan/gis/pipeline.h>
#include <groundplan/ground_plans.h>

#include <ogr_spatialref.h>

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace groundplan::output {

class StreamedGpkg final : public PlanFeed {
 public:
  struct Setup {
    SliceWrite write;             // dst (a new GeoPackage), flags (no layer names), layers; plans and writers unused
    int threads = 1;              // the run's threads: writers as gpkg_writers gives for that many plans
    std::size_t id_chars = 0;     // as the CLI's dataset (0: not a DBF)
    Translate translate;
  };
  explicit StreamedGpkg(Setup setup);
  /// Stops and joins the threads; unless finish() succeeded, removes the destination and the slices.
  ~StreamedGpkg() override;
  StreamedGpkg(const StreamedGpkg&) = delete;
  StreamedGpkg& operator=(const StreamedGpkg&) = delete;

  /// PipelineOptions::plan_feed: takes the result read (its footprints are read by the writers until finish: they
  /// must not move, as they do not in the pipeline) and returns this feed.
  PlanFeed* engage(const gis::PipelineResult& read);

  void begin(std::size_t blocks) override;
  void block_done(std::size_t b, const std::vector<GroundPlan>& plans) override;
  void end(bool complete) override;

  /// True when the union began and there are enough plans for two writers: the caller then finishes this write
  /// instead of writing the plans itself; false: nothing was written.
  bool engaged() const { return engaged_; }
  /// After the union: writes slice 0 where it carries other layers (`slice0` gives the caller's dataset over the whole
  /// result, restricted to the plans given), waits for the other slices and the appends. On failure nothing is left
  /// under the destination nor beside it.
  SliceOutcome finish(const SliceSource& slice0);

  std::size_t slices() const;             // written (0 before finish)
  std::size_t slices_before_end() const;  // of them, started before the union had ended
  int writers() const { return writers_; }

 private:
  void write_slices();                          // a writer thread
  void append_slices();                         // the appending thread
  bool write_one(std::size_t k, std::size_t first, std::size_t last, const SliceSource* whole);
  void fail(std::string why);

  Setup setup_;
  std::string table_;
  OGRSpatialReference srs_;
  const Footprint* fps_ = nullptr;
  std::size_t n_fps_ = 0;
  bool slice0_late_ = false;  // slice 0 carries other layers: written by finish()

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::vector<GroundPlan>> by_block_;  // the blocks' plans (copies), sized by begin()
  std::vector<char> done_;                          // block united
  std::vector<std::size_t> first_;                  // first plan of each block of the final prefix
  std::size_t prefix_ = 0;                          // blocks before this one are all united
  std::size_t ready_ = 0;                           // plans final: those of the prefix
  bool ended_ = false, failed_ = false, appended_ = false;
  std::string error_;
  std::size_t slice_plans_ = 0;             // plans a slice (the last one fewer)
  std::vector<char> written_;               // slice k written (grown as needed)
  std::size_t slices_total_ = 0;            // known once ended: ceil(plans / slice_plans), at least 1
  std::size_t early_ = 0;                   // slices started before the end
  std::atomic<std::size_t> next_slice_{0};
  bool engaged_ = false, finished_ok_ = false;
  int writers_ = 0;
  double t_begin_ = 0;
  std::vector<std::thread> threads_;
};

}  // namespace groundplan::output

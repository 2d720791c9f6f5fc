// SPDX-License-Identifier: MIT
// build_ground_plans: Algorithm 3.1 of the paper. Blocks from the raster backend (§5), then every
// block on its own (they are independent: tbb::parallel_for over blocks, largest first).
#include <groundplan/error.h>
#include <groundplan/ground_plans.h>
#include <groundplan/raster_backend.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <thread>

#include "robust/predicates.h"
#include "union/block_union.h"
#include "union/input_check.h"
#include "union/snap_round.h"

namespace groundplan {
std::vector<GroundPlan> build_ground_plans(const std::vector<Footprint>& footprints, const UnionParams& params,
                                           std::vector<Problem>& problems, const Progress& progress) {
  if (params.resolution_m < 0 || !std::isfinite(params.resolution_m))
    throw InvalidArgument("resolution_m must be >= 0 (0 = automatic), got " + std::to_string(params.resolution_m));
  if (params.threads < 0) throw InvalidArgument("threads must be >= 0 (0 = all cores)");
  const int threads = params.threads > 0 ? params.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);  // the passes over every footprint below run in it too: serial, they
                                   // were ~0.1 s of a 16-thread city run (tests/bench/RESULTS.md)
  // Footprints without area or with coordinates the exact arithmetic is not certified for take no
  // part; each is reported (nothing is dropped silently; issue 20: any input gets an answer).
  std::vector<Footprint> const* src = &footprints;
  std::vector<char> usable;
  FootprintSet all;
  arena.execute([&] {
    usable = detail::usable_footprints(footprints, problems);
    all = make_footprint_set(*src);
  });
  FootprintSet fps;
  fps.footprints = src;
  fps.indices.reserve(all.indices.size());
  fps.boxes.reserve(all.indices.size());
  for (std::size_t k = 0; k < all.indices.size(); ++k) {
    if (!usable[all.indices[k]]) continue;
    fps.indices.push_back(all.indices[k]);
    fps.boxes.push_back(all.boxes[k]);
  }
  // Snap rounding (issue 20): each block on the grid of its own largest coordinate magnitude, at most
  // the call's pitch g. A snapped block's vertices move by up to g/sqrt(2); boxes grown by 4g put
  // footprints closer than that into one block, so that blocks stay more than 2g apart and their
  // roundings never meet.
  double max_abs = 0;
  std::vector<double> magnitude(footprints.size(), 0);  // per footprint, for its block's pitch
  for (std::size_t k = 0; k < fps.boxes.size(); ++k) {
    const FootprintSet::Box& b = fps.boxes[k];
    const double m = std::max({std::fabs(b.minx), std::fabs(b.miny), std::fabs(b.maxx), std::fabs(b.maxy)});
    magnitude[fps.indices[k]] = m;
    max_abs = std::max(max_abs, m);
  }
  const double pitch = detail::snap_pitch(max_abs);
  for (FootprintSet::Box& b : fps.boxes) {
    b.minx -= 4 * pitch;
    b.miny -= 4 * pitch;
    b.maxx += 4 * pitch;
    b.maxy += 4 * pitch;
  }
  const PixelGrid grid = make_pixel_grid(fps, params.resolution_m);
  const auto t_blocks = std::chrono::steady_clock::now();  // starting the backend counts: CUDA takes ~0.3 s
  std::unique_ptr<RasterBackend> backend = make_raster_backend(params.device);
  std::vector<Block> blocks = backend->find_blocks(fps, grid, progress.sub(0.0, 0.1));
  const auto t_union = std::chrono::steady_clock::now();
  if (params.stats) {
    params.stats->blocks = blocks.size();
    params.stats->blocks_s = std::chrono::duration<double>(t_union - t_blocks).count();
    params.stats->backend = backend->name();
  }

  // Largest blocks first, so that one big block does not finish last on one core. With a feed, only the large ones
  // (the rest in block order, taken from one queue below), so that the plans are final from the first block on
  // while the union goes on. Without one, all of them: that order unites a city ~10-15 % faster (RESULTS.md,
  // "Written while the union goes on").
  const std::size_t large = params.feed ? std::max<std::size_t>(64, fps.indices.size() / (16 * static_cast<std::size_t>(threads)))
                                        : 0;
  std::vector<std::size_t> order(blocks.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto large_end = std::stable_partition(order.begin(), order.end(),
                                               [&](std::size_t b) { return blocks[b].footprints.size() >= large; });
  std::stable_sort(order.begin(), large_end,
                   [&](std::size_t a, std::size_t b) { return blocks[a].footprints.size() > blocks[b].footprints.size(); });

  struct FeedEnd {  // the feed is told the end also when a block's union throws or the run is cancelled
    PlanFeed* feed;
    ~FeedEnd() {
      if (feed) feed->end(false);
    }
  } feed_end{params.feed};
  if (params.feed) params.feed->begin(blocks.size());

  std::vector<detail::BlockResult> results(blocks.size());
  std::atomic<std::size_t> done{0};
  const std::thread::id caller = std::this_thread::get_id();
  const Progress stage = progress.sub(0.1, 1.0);
  auto one = [&](std::size_t oi) {
    const std::size_t bi = order[oi];
    try {
      double block_abs = 0;
      for (std::uint32_t fi : blocks[bi].footprints) block_abs = std::max(block_abs, magnitude[fi]);
      results[bi] = detail::union_block(*src, blocks[bi].footprints, detail::snap_pitch(block_abs));
    } catch (const TopologyError& e) {
      detail::BlockResult r;
      for (std::uint32_t fi : blocks[bi].footprints)
        r.problems.push_back(Problem{footprints[fi].source_id, footprints[fi].source_file, "union", "UNION_FAILED",
                                     std::string("the union of this footprint's block failed: ") + e.what()});
      results[bi] = std::move(r);
    }
    if (params.feed) params.feed->block_done(bi, results[bi].plans);
    const std::size_t d = ++done;
    if (progress && std::this_thread::get_id() == caller && (d % 64 == 0 || d == blocks.size()))
      stage.report(static_cast<double>(d) / static_cast<double>(blocks.size()), "union of blocks");
  };
  if (threads == 1 || blocks.size() <= 1) {
    for (std::size_t oi = 0; oi < blocks.size(); ++oi) one(oi);
  } else if (!params.feed) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size(), 1),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t oi = r.begin(); oi != r.end(); ++oi) one(oi);
                        });
    });
  } else {
    // One queue: every thread takes the next task, a large block or a run of kRun small ones in `order`, so that
    // blocks finish close to that order; a run keeps neighbouring blocks (and their footprints) on one core. A throw
    // (a cancel) stops the other threads at their next task.
    constexpr std::size_t kRun = 16;
    const auto n_large = static_cast<std::size_t>(large_end - order.begin());
    const std::size_t tasks = n_large + (blocks.size() - n_large + kRun - 1) / kRun;
    std::atomic<std::size_t> next{0};
    std::atomic<bool> stop{false};
    arena.execute([&] {
      tbb::parallel_for(0, threads, [&](int) {
        while (!stop.load(std::memory_order_relaxed)) {
          const std::size_t t = next.fetch_add(1, std::memory_order_relaxed);
          if (t >= tasks) break;
          const std::size_t lo = t < n_large ? t : n_large + (t - n_large) * kRun;
          const std::size_t hi = t < n_large ? t + 1 : std::min(blocks.size(), lo + kRun);
          try {
            for (std::size_t oi = lo; oi < hi; ++oi) one(oi);
          } catch (...) {
            stop = true;
            throw;
          }
        }
      }, tbb::simple_partitioner());
    });
  }
  if (params.feed) params.feed->end(true);  // every block's plans told: the feed's last waiters go on now
  feed_end.feed = nullptr;
  // The plans in block order: moved into place side by side (offsets first), problems in order after.
  std::vector<std::size_t> first(results.size() + 1, 0);
  for (std::size_t bi = 0; bi < results.size(); ++bi) first[bi + 1] = first[bi] + results[bi].plans.size();
  std::vector<GroundPlan> plans(first.back());
  std::vector<char> member(footprints.size(), 0);  // a footprint is in one block: no two blocks write one entry
  std::vector<char> failed(footprints.size(), 0);
  std::vector<double> snapped_at(footprints.size(), 0);  // the pitch of a snap-rounded group it bordered
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, results.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t bi = r.begin(); bi != r.end(); ++bi) {
        std::size_t at = first[bi];
        for (GroundPlan& g : results[bi].plans) {
          for (std::uint32_t m : g.members) member[m] = 1;
          plans[at++] = std::move(g);
        }
      }
    });
  });
  for (std::size_t bi = 0; bi < results.size(); ++bi) {
    for (std::uint32_t fi : results[bi].snapped) snapped_at[fi] = results[bi].pitch;
    for (Problem& p : results[bi].problems) {
      if (p.code == "UNION_FAILED")
        for (std::uint32_t fi : blocks[bi].footprints) failed[fi] = 1;
      problems.push_back(std::move(p));
    }
  }
  // Nothing is dropped silently: a footprint with non-collinear points can still have no area
  // under the even-odd rule (rings that retrace themselves: A-B-C-B), or be narrower than the snap
  // grid of its coordinates everywhere (issue 20: features narrower than the pitch collapse). It is in
  // no plan; say so.
  for (std::uint32_t fi : fps.indices) {
    if (member[fi] || failed[fi]) continue;
    std::string why = "the footprint's rings enclose no area (they retrace or cancel themselves): not in any plan";
    if (snapped_at[fi] > 0) {
      char g[32];
      std::snprintf(g, sizeof g, "%.3g", snapped_at[fi]);
      why = std::string("the footprint is narrower than the snap-rounding grid of its coordinates (") + g +
            " m, 16 units in the last place) and collapsed, or its rings cancel themselves: not in any plan";
    }
    problems.push_back(Problem{footprints[fi].source_id, footprints[fi].source_file, "union", "NO_AREA", why});
  }
  progress.report(1.0, "ground plans");
  if (params.stats)
    params.stats->union_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_union).count();
  return plans;
}

double snap_pitch(double max_abs) { return detail::snap_pitch(max_abs); }

}  // namespace groundplan

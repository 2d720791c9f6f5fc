// SPDX-License-Identifier: MIT
// The tiled run over ranks (issue 15 stage 2) without MPI: how the files are cut among ranks, the group question
// the reduce tree asks, the records ranks send each other, and the whole run over ranks played by threads
// (ThreadExchange) against the run in one process.
#include "pipeline/plan_spill.h"
#include "pipeline/tile_extents.h"
#include "pipeline/tile_ranks.h"

#include <groundplan/error.h>
#include <groundplan/gis/tiled.h>

#include "test_support.h"

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <random>
#include <thread>

namespace groundplan::gis::detail {
namespace {

TEST(SplitByBytes, NearestBoundaryAndAFileForEveryRank) {
  // The Niedersachsen 4 tiles' sizes: by bytes alone the last rank would get nothing (the last file is 58 %).
  const std::vector<std::uint64_t> sizes{50208, 795879, 1163844, 2744475};
  EXPECT_EQ(split_by_bytes(sizes, 4, 0), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(split_by_bytes(sizes, 2, 0), (std::vector<std::size_t>{0, 3, 4}));
  EXPECT_EQ(split_by_bytes(sizes, 1, 0), (std::vector<std::size_t>{0, 4}));
  const std::vector<std::uint64_t> equal(8, 100);
  EXPECT_EQ(split_by_bytes(equal, 4, 0), (std::vector<std::size_t>{0, 2, 4, 6, 8}));
  // Rank 0 read the first 3 files to fix the working CRS: they are its own.
  EXPECT_EQ(split_by_bytes(equal, 4, 3), (std::vector<std::size_t>{0, 3, 4, 6, 8}));
  // Fewer files than ranks: each file once (at the byte halves: ranks 0 and 2), the other ranks idle.
  EXPECT_EQ(split_by_bytes({10, 10}, 4, 0), (std::vector<std::size_t>{0, 1, 1, 2, 2}));
}

TEST(SplitByBytes, ContiguousCoverOnRandomSizes) {
  std::mt19937_64 rng(15);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<std::uint64_t> sizes(rng() % 40);
    for (auto& s : sizes) s = rng() % 3 ? rng() % 1000 : rng() % 1000000;
    const int ranks = 1 + static_cast<int>(rng() % 17);
    const std::size_t first_free = sizes.empty() ? 0 : rng() % (sizes.size() + 1);
    const std::vector<std::size_t> b = split_by_bytes(sizes, ranks, first_free);
    ASSERT_EQ(b.size(), static_cast<std::size_t>(ranks) + 1);
    EXPECT_EQ(b.front(), 0u);
    EXPECT_EQ(b.back(), sizes.size());
    for (int r = 0; r < ranks; ++r) {
      EXPECT_LE(b[r], b[r + 1]);
      // a file for every rank where there are files enough: N in all, N - 1 beyond rank 0's first ones
      const std::size_t n = sizes.size(), nr = static_cast<std::size_t>(ranks);
      if (n >= nr && n - first_free >= nr - 1) EXPECT_LT(b[r], b[r + 1]) << trial;
    }
    if (ranks > 1) EXPECT_GE(b[1], std::min(first_free, sizes.size()));
  }
}

TEST(TileExtents, MeetsOutsideAGroupOfTiles) {
  const TileExtents index({{0, 0, 100, 100}, {100, 0, 200, 100}, {200, 0, 300, 100}, {300, 0, 400, 100}});
  const Box across_1_2{150, 40, 250, 60};
  EXPECT_TRUE(index.meets_outside(across_1_2, 1, 2));   // tile 2 is outside {1}
  EXPECT_FALSE(index.meets_outside(across_1_2, 1, 3));  // {1, 2}: final there
  EXPECT_TRUE(index.meets_outside({190, 40, 300, 60}, 1, 3));  // touches tile 3 at x = 300
  EXPECT_FALSE(index.meets_outside({190, 40, 300, 60}, 0, 4));
}

Footprint square(const std::string& id, double x, double y, double side) {
  Footprint f;
  f.source_id = id;
  f.source_file = "t.gml";
  f.method = "ground-surface";
  f.min_z = x;
  f.max_z = x + 1;
  f.polygons = {Polygon{{{x, y}, {x + side, y}, {x + side, y + side}, {x, y + side}}, {}}};
  return f;
}

TEST(PlanSpill, EncodedRecordsTravelAndAppendAsWritten) {
  const Footprint a = square("A", 0, 0, 1), b = square("B", 1, 0, 1);
  GroundPlan gp;
  gp.polygon = Polygon{{{0, 0}, {2, 0}, {2, 1}, {0, 1}}, {}};
  gp.members = {5, 9};
  gp.area_m2 = 2;
  std::vector<char> bytes;
  PlanSpill::encode(gp, {&a, &b}, 7, {0, 0, 2, 1}, bytes);
  const std::size_t first = bytes.size();
  gp.members = {11};
  PlanSpill::encode(gp, {&b}, 8, {1, 0, 2, 1}, bytes);
  EXPECT_EQ(PlanSpill::record_length(bytes.data(), bytes.size()), first);
  const std::vector<SpilledPlan> got = PlanSpill::decode_all(bytes, true);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].ids, (std::vector<std::uint32_t>{5, 9}));
  EXPECT_EQ(got[0].tile, 7u);
  EXPECT_EQ(got[0].footprints[1].source_id, "B");
  EXPECT_EQ(got[0].footprints[1].polygons[0].outer, b.polygons[0].outer);
  EXPECT_EQ(got[1].ids, (std::vector<std::uint32_t>{11}));
  EXPECT_EQ(got[1].box, (Box{1, 0, 2, 1}));
  // What a rank receives goes into rank 0's spill byte for byte.
  PlanSpill spill;
  const std::uint64_t at = spill.append_encoded(bytes.data() + first, bytes.size() - first);
  spill.flush();
  const SpilledPlan back = spill.read(at, true);
  EXPECT_EQ(back.ids, got[1].ids);
  EXPECT_EQ(back.footprints[0].polygons[0].outer, b.polygons[0].outer);
  // Cut short: refused, never read past the end.
  EXPECT_THROW(PlanSpill::decode_all(std::vector<char>(bytes.begin(), bytes.end() - 3), true), Error);
}

TEST(Packer, CountsAndProblemsRoundTrip) {
  Packer p;
  p.put(std::uint64_t{42});
  p.str("EPSG:25832");
  p.problems({{"b1", "t.gml", "read", "UNREADABLE_FILE", "cut short"}, {"", "u.gml", "read", "NOTE", "guess"}});
  p.put(2.5);
  Unpacker u(p.bytes.data(), p.bytes.size());
  EXPECT_EQ(u.get<std::uint64_t>(), 42u);
  EXPECT_EQ(u.str(), "EPSG:25832");
  std::vector<Problem> got;
  u.problems(got);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].code, "UNREADABLE_FILE");
  EXPECT_EQ(got[1].file, "u.gml");
  EXPECT_EQ(u.get<double>(), 2.5);
  EXPECT_THROW(u.get<char>(), Error);
}

/// N ranks played by N threads of this process: what MpiExchange does, through shared memory.
class ThreadRanks {
 public:
  explicit ThreadRanks(int n) : n_(n), parts_(static_cast<std::size_t>(n)) {}
  class Rank final : public TileExchange {
   public:
    Rank(ThreadRanks& all, int me) : all_(all), me_(me) {}
    int rank() const override { return me_; }
    int size() const override { return all_.n_; }
    std::vector<char> allgather(const std::vector<char>& mine, std::vector<std::uint64_t>* sizes) override {
      std::unique_lock lock(all_.m_);
      const std::uint64_t round = all_.round_;
      all_.parts_[static_cast<std::size_t>(me_)] = mine;
      if (++all_.arrived_ == all_.n_) {
        all_.gathered_.clear();
        all_.sizes_.clear();
        for (const auto& p : all_.parts_) {
          all_.gathered_.insert(all_.gathered_.end(), p.begin(), p.end());
          all_.sizes_.push_back(p.size());
        }
        all_.arrived_ = 0;
        ++all_.round_;
        all_.cv_.notify_all();
      } else {
        all_.cv_.wait(lock, [&] { return all_.round_ != round; });
      }
      if (sizes) *sizes = all_.sizes_;
      return all_.gathered_;  // read before the next round can start: every rank must arrive there first
    }
    void send(int to, const std::vector<char>& bytes) override {
      std::lock_guard lock(all_.m_);
      all_.mail_[{me_, to}].push_back(bytes);
      all_.cv_.notify_all();
    }
    std::vector<char> receive(int from) override {
      std::unique_lock lock(all_.m_);
      auto& box = all_.mail_[{from, me_}];
      all_.cv_.wait(lock, [&] { return !box.empty(); });
      std::vector<char> b = std::move(box.front());
      box.pop_front();
      return b;
    }
    void tell_progress(std::uint64_t bytes_read, bool last) override {
      std::lock_guard lock(all_.m_);
      all_.words_.push_back({me_, bytes_read, last});
      all_.cv_.notify_all();
    }
    void heard_progress(bool until_last, const std::function<void(std::uint64_t)>& more) override {
      std::unique_lock lock(all_.m_);
      all_.heard_.resize(static_cast<std::size_t>(all_.n_), 0);
      for (;;) {
        if (until_last) all_.cv_.wait(lock, [&] { return !all_.words_.empty() || all_.last_words_ == all_.n_ - 1; });
        if (all_.words_.empty()) return;
        const Word w = all_.words_.front();
        all_.words_.pop_front();
        all_.last_words_ += w.last ? 1 : 0;
        std::uint64_t& was = all_.heard_[static_cast<std::size_t>(w.from)];
        const std::uint64_t n = w.bytes > was ? w.bytes - was : 0;
        was = std::max(was, w.bytes);
        lock.unlock();
        if (n) more(n);
        lock.lock();
      }
    }

   private:
    ThreadRanks& all_;
    int me_;
  };

 private:
  int n_;
  std::mutex m_;
  std::condition_variable cv_;
  int arrived_ = 0;
  std::uint64_t round_ = 0;
  std::vector<std::vector<char>> parts_;
  std::vector<char> gathered_;
  std::vector<std::uint64_t> sizes_;
  std::map<std::pair<int, int>, std::deque<std::vector<char>>> mail_;
  struct Word {
    int from;
    std::uint64_t bytes;
    bool last;
  };
  std::deque<Word> words_;          // tell_progress words not heard yet
  std::vector<std::uint64_t> heard_;  // each rank's count as rank 0 heard it
  int last_words_ = 0;
};

/// Plans as comparable rows: members (global indices) and member ids, area, the outer ring's vertex set.
std::vector<std::string> plan_rows(const TiledResult& r) {
  std::vector<std::string> rows;
  for (std::size_t i = 0; i < r.plan_count(); ++i) {
    const StoredPlan p = r.plan(i);
    std::string row = std::to_string(p.plan.area_m2) + " |";
    for (std::size_t k = 0; k < p.plan.members.size(); ++k)
      row += " " + std::to_string(p.plan.members[k]) + "=" + p.member_ids[k];
    std::vector<std::string> pts;
    for (const Point2& q : p.plan.polygon.outer) pts.push_back(std::to_string(q.x) + "," + std::to_string(q.y));
    std::sort(pts.begin(), pts.end());
    for (const std::string& s : pts) row += " " + s;
    row += " holes " + std::to_string(p.plan.polygon.holes.size());
    rows.push_back(row);
  }
  std::sort(rows.begin(), rows.end());
  return rows;
}

/// test_tiles.py's generated city: courtyard blocks on a 45 m pitch across 100 m tiles, a row of 15 houses
/// across three tiles; one GeoJSON file a tile.
std::string city(const test::TempDir& dir) {
  struct B { double x0, y0, x1, y1; };
  std::vector<B> bs;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const double x0 = 5 + 45 * i, y0 = 5 + 45 * j;
      bs.push_back({x0, y0, x0 + 30, y0 + 8});
      bs.push_back({x0, y0 + 22, x0 + 30, y0 + 30});
      bs.push_back({x0, y0 + 8, x0 + 8, y0 + 22});
      bs.push_back({x0 + 22, y0 + 8, x0 + 30, y0 + 22});
    }
  for (int k = 0; k < 15; ++k) bs.push_back({20.0 * k, 280, 20.0 * k + 20, 290});
  std::map<std::pair<int, int>, std::string> tiles;
  for (std::size_t n = 0; n < bs.size(); ++n) {
    const B& b = bs[n];
    const auto key = std::make_pair(static_cast<int>((b.x0 + b.x1) / 2 / 100), static_cast<int>((b.y0 + b.y1) / 2 / 100));
    auto xy = [](double x, double y) { return "[" + std::to_string(500000 + x) + "," + std::to_string(5800000 + y) + "]"; };
    std::string& f = tiles[key];
    if (!f.empty()) f += ",";
    f += R"({"type":"Feature","properties":{"bid":"b)" + std::to_string(n) + R"("},"geometry":{"type":"Polygon","coordinates":[[)" +
         xy(b.x0, b.y0) + "," + xy(b.x1, b.y0) + "," + xy(b.x1, b.y1) + "," + xy(b.x0, b.y1) + "," + xy(b.x0, b.y0) + "]]}}";
  }
  for (const auto& [key, features] : tiles)
    dir.file("city/tile_" + std::to_string(key.first) + "_" + std::to_string(key.second) + ".geojson",
             R"({"type":"FeatureCollection","crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::25832"}},"features":[)" +
                 features + "]}");
  return (dir.path / "city").string();
}

/// Runs `options` over n ranks played by threads; every rank's result, in rank order.
std::vector<std::unique_ptr<TiledResult>> over_thread_ranks(const PipelineOptions& options, int n, FinalPlans where,
                                                            const Progress& rank_0_progress = {}) {
  ThreadRanks all(n);
  std::vector<std::unique_ptr<TiledResult>> results(static_cast<std::size_t>(n));
  std::vector<std::string> errors(static_cast<std::size_t>(n));
  std::vector<std::thread> threads;
  for (int r = 0; r < n; ++r)
    threads.emplace_back([&, r] {
      ThreadRanks::Rank me(all, r);
      try {
        results[static_cast<std::size_t>(r)] = run_pipeline_tiled(options, me, r == 0 ? rank_0_progress : Progress{},
                                                                  where);
      } catch (const std::exception& e) {
        errors[static_cast<std::size_t>(r)] = e.what();
      }
    });
  for (std::thread& t : threads) t.join();
  for (int r = 0; r < n; ++r) EXPECT_EQ(errors[static_cast<std::size_t>(r)], "") << n << " ranks, rank " << r;
  return results;
}

/// The tiled run of city(dir), one thread, building ids from the "bid" field.
PipelineOptions city_options(const test::TempDir& dir) {
  PipelineOptions options;
  options.inputs = {city(dir)};
  options.ogr_input.id_field = "bid";
  options.threads = 1;
  return options;
}

TEST(TiledRunOverRanks, ThreadsAsRanksGiveTheOneProcessPlans) {
  GDALAllRegister();
  const test::TempDir dir("groundplan_tile_ranks");
  const PipelineOptions options = city_options(dir);
  const std::unique_ptr<TiledResult> one = run_pipeline_tiled(options);
  const std::vector<std::string> expected = plan_rows(*one);
  ASSERT_EQ(expected.size(), 37u);
  EXPECT_GT(one->tiles.seam_plans, 0u);
  for (int n : {2, 3, 4, 5, 9, 12}) {
    const auto results = over_thread_ranks(options, n, FinalPlans::to_rank_0);
    for (const auto& r : results) ASSERT_TRUE(r) << n << " ranks";
    const TiledResult& r0 = *results[0];
    EXPECT_EQ(plan_rows(r0), expected) << n << " ranks";
    EXPECT_EQ(r0.footprints, one->footprints);
    EXPECT_EQ(r0.buildings_read, one->buildings_read);
    EXPECT_EQ(r0.members_before(r0.plan_count()), one->members_before(one->plan_count()));
    EXPECT_EQ(r0.tiles.final_plans + r0.tiles.reduced_plans, expected.size());
    EXPECT_EQ(r0.tiles.final_plans, one->tiles.final_plans);
    EXPECT_EQ(r0.tiles.seam_plans, one->tiles.seam_plans);
    EXPECT_EQ(r0.ranks.size(), static_cast<std::size_t>(n));
    for (int r = 1; r < n; ++r) EXPECT_EQ(results[static_cast<std::size_t>(r)]->plan_count(), 0u);
  }
}


// Stage 5 (every rank writes its own plans into a database): each rank keeps its final plans, and
// plan_number/row_number put each where rank 0 has it when the plans are gathered, with the same global members;
// together the ranks hold every plan once.
TEST(TiledRunOverRanks, KeptPlansAreNumberedAsRankZeroGathersThem) {
  GDALAllRegister();
  const test::TempDir dir("groundplan_tile_ranks_kept");
  const PipelineOptions options = city_options(dir);
  for (int n : {2, 3, 5}) {
    const auto gathered = over_thread_ranks(options, n, FinalPlans::to_rank_0);
    const auto kept = over_thread_ranks(options, n, FinalPlans::kept_by_each_rank);
    ASSERT_TRUE(gathered[0] && kept[0]);
    const TiledResult& g = *gathered[0];
    ASSERT_EQ(g.plan_count(), 37u);
    std::vector<int> seen(g.plan_count(), 0);
    std::size_t on_other_ranks = 0;
    for (int r = 0; r < n; ++r) {
      const TiledResult& k = *kept[static_cast<std::size_t>(r)];
      if (r > 0) on_other_ranks += k.plan_count();
      for (std::size_t i = 0; i < k.plan_count(); ++i) {
        const std::uint64_t at = k.plan_number(i);
        ASSERT_LT(at, g.plan_count()) << n << " ranks, rank " << r;
        ++seen[at];
        const StoredPlan a = k.plan(i), b = g.plan(static_cast<std::size_t>(at));
        EXPECT_EQ(a.plan.members, b.plan.members) << n << " ranks, rank " << r << " plan " << i;
        EXPECT_EQ(a.member_ids, b.member_ids);
        EXPECT_EQ(a.plan.polygon.outer, b.plan.polygon.outer);
        EXPECT_EQ(k.row_number(i), g.members_before(static_cast<std::size_t>(at)));
      }
    }
    EXPECT_EQ(seen, std::vector<int>(g.plan_count(), 1)) << n << " ranks: every plan once";
    EXPECT_GT(on_other_ranks, 0u);  // not all on rank 0: the others write theirs
    // rank 0 still has the counts of all ranks
    EXPECT_EQ(kept[0]->tiles.final_plans + kept[0]->tiles.reduced_plans, g.plan_count());
    EXPECT_EQ(kept[0]->footprints, g.footprints);
  }
}

// -progress over ranks: only rank 0 shows it, and its reading part (0 to 0.9) counts every rank's bytes, which
// each rank tells it as it reads (TileExchange::tell_progress). Counting its own alone, it would stop near its own
// share (about 1/n of the bytes) and jump to 0.9 at "seams".
TEST(TiledRunOverRanks, RankZeroShowsTheBytesEveryRankRead) {
  GDALAllRegister();
  const test::TempDir dir("groundplan_tile_ranks_progress");
  const PipelineOptions options = city_options(dir);
  for (int n : {1, 2, 4, 9}) {
    std::mutex m;
    std::vector<std::pair<double, std::string>> seen;
    const Progress progress([&](double f, const char* message) {
      std::lock_guard lock(m);
      seen.emplace_back(f, message ? message : "");
      return true;
    });
    const auto results = over_thread_ranks(options, n, FinalPlans::to_rank_0, progress);
    ASSERT_TRUE(results[0]) << n << " ranks";
    double read = -1;
    bool seams = false;
    for (const auto& [f, message] : seen) {
      if (message == "seams") {
        seams = true;
        break;
      }
      EXPECT_GE(f, read) << n << " ranks: progress went back";
      read = f;
    }
    EXPECT_TRUE(seams) << n << " ranks";
    EXPECT_NEAR(read, 0.9, 1e-12) << n << " ranks: the reading part ended short of every rank's bytes";
  }
}

}  // namespace
}  // namespace groundplan::gis::detail

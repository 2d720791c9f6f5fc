// SPDX-License-Identifier: MIT
// The GeoPackage written while the union goes on (driver/output/streamed_gpkg.h), fed here by hand: blocks told in
// any order from several threads (empty blocks, blocks of several plans, slices that wait for a late block) give
// the file one ogr2ogr writes from the whole result, row for row; a union that stops leaves no file; few plans
// leave the write to the caller. (tests/e2e/test_gpkg_writers.py runs it through the CLI and the real union.)
#include <streamed_gpkg.h>

#include <ogr_groundplan.h>

#include <gtest/gtest.h>

#include <gdal.h>
#include <gdal_utils.h>
#include <ogr_spatialref.h>
#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"

namespace groundplan {
namespace {

bool translate(const std::string& dst, GDALDatasetH src, const std::vector<std::string>& args, bool, int* usage) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  GDALVectorTranslateOptions* o = GDALVectorTranslateOptionsNew(argv.data(), nullptr);
  if (!o) return false;
  GDALDatasetH out = GDALVectorTranslate(dst.c_str(), nullptr, 1, &src, o, usage);
  GDALVectorTranslateOptionsFree(o);
  if (!out) return false;
  GDALClose(out);
  return true;
}

/// `n` footprints (squares on a grid) and their plans, one each, cut into blocks of 0 to 3 plans; plus two
/// problems.
struct Fed {
  std::shared_ptr<gis::PipelineResult> result = std::make_shared<gis::PipelineResult>();
  std::vector<std::vector<GroundPlan>> blocks;
};

Fed make_fed(std::size_t n) {
  Fed f;
  gis::PipelineResult& r = *f.result;
  OGRSpatialReference srs;
  srs.importFromEPSG(25832);
  char* wkt = nullptr;
  srs.exportToWkt(&wkt);
  r.crs_wkt = wkt;
  CPLFree(wkt);
  std::mt19937 rng(5);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = 400000 + 10.0 * static_cast<double>(i % 300), y = 5800000 + 10.0 * static_cast<double>(i / 300);
    Footprint fp;
    fp.source_id = "b" + std::to_string(i);
    fp.source_file = "grid.gml";
    fp.min_z = static_cast<double>(i % 7);
    fp.max_z = fp.min_z + 9;
    Polygon sq;
    sq.outer = {{x, y}, {x + 6, y}, {x + 6, y + 6}, {x, y + 6}};
    fp.polygons.push_back(sq);
    r.footprints.push_back(fp);
    GroundPlan gp;
    gp.polygon = sq;
    gp.members = {static_cast<std::uint32_t>(i)};
    gp.area_m2 = 36;
    r.plans.push_back(gp);
  }
  r.problems.push_back(Problem{"x1", "grid.gml", "read", "NO_GEOMETRY", "no geometry"});
  r.problems.push_back(Problem{"x2", "grid.gml", "union", "NO_AREA", "no area"});
  for (std::size_t i = 0; i < n;) {
    const std::size_t k = std::min<std::size_t>(rng() % 4, n - i);  // 0..3 plans: empty blocks too
    f.blocks.emplace_back(r.plans.begin() + static_cast<std::ptrdiff_t>(i), r.plans.begin() + static_cast<std::ptrdiff_t>(i + k));
    i += k;
  }
  return f;
}

/// Tells `feed` the blocks in a shuffled order from 4 threads, then the end.
void feed_shuffled(PlanFeed& feed, const Fed& f, unsigned seed) {
  feed.begin(f.blocks.size());
  std::vector<std::size_t> order(f.blocks.size());
  for (std::size_t b = 0; b < order.size(); ++b) order[b] = b;
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (std::size_t k = t; k < order.size(); k += 4) feed.block_done(order[k], f.blocks[order[k]]);
    });
  for (auto& t : threads) t.join();
  feed.end(true);
}

/// Every row of `table`, in FID order, as text.
std::vector<std::string> rows(const std::string& path, const std::string& table) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  const std::string sql = "SELECT * FROM \"" + table + "\" ORDER BY 1";
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  std::vector<std::string> out;
  while (s && sqlite3_step(s) == SQLITE_ROW) {
    std::string row;
    for (int c = 0; c < sqlite3_column_count(s); ++c) {
      const void* blob = sqlite3_column_blob(s, c);
      row.append(static_cast<const char*>(blob), static_cast<std::size_t>(sqlite3_column_bytes(s, c)));
      row += '|';
    }
    out.push_back(row);
  }
  sqlite3_finalize(s);
  sqlite3_close(db);
  return out;
}

output::StreamedGpkg::Setup setup(const std::string& dst, std::vector<std::string> layers) {
  output::StreamedGpkg::Setup s;
  s.write.dst = dst;
  s.write.flags = {"-f", "GPKG", "-lco", "SPATIAL_INDEX=NO"};
  s.write.layers = std::move(layers);
  s.threads = 4;
  s.translate = translate;
  return s;
}

/// What one ogr2ogr writes from the whole result.
std::string reference(const test::TempDir& dir, const Fed& f, const std::vector<std::string>& layers) {
  const std::string ref = (dir.path / "ref.gpkg").string();
  auto* ds = new driver::OGRGroundPlanDataSource("GROUNDPLAN:grid", f.result, 0, 1);
  std::vector<std::string> args = {"-f", "GPKG", "-lco", "SPATIAL_INDEX=NO"};
  args.insert(args.end(), layers.begin(), layers.end());
  int usage = 0;
  EXPECT_TRUE(translate(ref, GDALDataset::ToHandle(ds), args, false, &usage));
  GDALClose(GDALDataset::ToHandle(ds));
  return ref;
}

std::vector<std::string> files_in(const test::TempDir& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir.path)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(StreamedGpkg, BlocksInAnyOrderGiveTheFileOfOneWriter) {
  GDALAllRegister();
  test::TempDir dir("streamed_gpkg");
  const Fed f = make_fed(30000);
  const std::string ref = reference(dir, f, {"ground_plans"});
  for (unsigned seed : {1u, 2u}) {
    const std::string dst = (dir.path / ("s" + std::to_string(seed) + ".gpkg")).string();
    output::StreamedGpkg w(setup(dst, {"ground_plans"}));
    ASSERT_EQ(w.engage(*f.result), &w);
    feed_shuffled(w, f, seed);
    ASSERT_TRUE(w.engaged());
    const output::SliceOutcome out = w.finish({});
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_GE(w.writers(), 2);
    EXPECT_GE(w.slices(), 3u);  // several slices: the appending ran beside the writing
    EXPECT_EQ(rows(dst, "ground_plans"), rows(ref, "ground_plans"));
    EXPECT_EQ(rows(dst, "ground_plans").size(), f.result->plans.size());
    EXPECT_EQ(rows(dst, "gpkg_ogr_contents"), rows(ref, "gpkg_ogr_contents"));
  }
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"ref.gpkg", "s1.gpkg", "s2.gpkg"})) << "a slice was left";
}

TEST(StreamedGpkg, OtherLayersGoWithSliceZeroAfterTheUnion) {
  GDALAllRegister();
  test::TempDir dir("streamed_gpkg");
  const Fed f = make_fed(30000);
  const std::vector<std::string> layers = {"ground_plans", "problems"};
  const std::string ref = reference(dir, f, layers);
  const std::string dst = (dir.path / "late.gpkg").string();
  output::StreamedGpkg w(setup(dst, layers));
  w.engage(*f.result);
  feed_shuffled(w, f, 3);
  const output::SliceSource slice0 = [&](std::size_t first, std::size_t last) -> GDALDatasetH {
    auto* ds = new driver::OGRGroundPlanDataSource("GROUNDPLAN:grid", f.result, 0, 1);
    ds->layer("ground_plans")->restrict_to(first, last);
    return GDALDataset::ToHandle(ds);
  };
  const output::SliceOutcome out = w.finish(slice0);
  ASSERT_TRUE(out.ok) << out.error;
  EXPECT_EQ(rows(dst, "ground_plans"), rows(ref, "ground_plans"));
  EXPECT_EQ(rows(dst, "problems"), rows(ref, "problems"));
  EXPECT_EQ(rows(dst, "problems").size(), 2u);
}

TEST(StreamedGpkg, AUnionThatStopsLeavesNoFile) {
  GDALAllRegister();
  test::TempDir dir("streamed_gpkg");
  const Fed f = make_fed(30000);
  const std::string dst = (dir.path / "stopped.gpkg").string();
  {
    output::StreamedGpkg w(setup(dst, {"ground_plans"}));
    w.engage(*f.result);
    w.begin(f.blocks.size());
    for (std::size_t b = 0; b < f.blocks.size() / 2; ++b) w.block_done(b, f.blocks[b]);  // slices get written
    w.end(false);
    const output::SliceOutcome out = w.finish({});
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("union stopped"), std::string::npos) << out.error;
  }
  EXPECT_TRUE(files_in(dir).empty()) << files_in(dir).front();
}

TEST(StreamedGpkg, FewPlansAreLeftToTheCaller) {
  GDALAllRegister();
  test::TempDir dir("streamed_gpkg");
  const Fed f = make_fed(3000);
  const std::string dst = (dir.path / "few.gpkg").string();
  output::StreamedGpkg w(setup(dst, {"ground_plans"}));
  w.engage(*f.result);
  feed_shuffled(w, f, 4);
  EXPECT_FALSE(w.engaged());
  EXPECT_TRUE(files_in(dir).empty());
}

}  // namespace
}  // namespace groundplan

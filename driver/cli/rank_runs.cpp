// SPDX-License-Identifier: MIT
#include "rank_runs.h"

#include "gpkg_rank_slices.h"
#include "gpkg_rtree.h"
#include "gpkg_slices.h"
#include "rank_writes.h"
#include "report.h"
#include "staged_output.h"
#include "timing.h"
#include "write_output.h"

#include "open_options.h"

#include <groundplan/gis/tiled.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <unistd.h>

namespace groundplan::cli {
namespace {

using gis::PipelineOptions;

/// A tiled result without plans or problems, in `like`'s CRS: the layers rank 0 makes the tables from.
class NoPlans final : public groundplan::gis::TiledResult {
 public:
  explicit NoPlans(const groundplan::gis::TiledResult& like) {
    crs_wkt = like.crs_wkt;
    crs_name = like.crs_name;
  }
  std::size_t plan_count() const override { return 0; }
  groundplan::gis::StoredPlan plan(std::size_t) const override { throw std::out_of_range("NoPlans has no plan"); }
  std::uint64_t members_before(std::size_t) const override { return 0; }
};

/// The tiled run over ranks, every rank keeping its own final plans to write them itself.
std::shared_ptr<const groundplan::gis::TiledResult> tiled_kept_by_each_rank(const PipelineOptions& options,
                                                                        const Progress& progress,
                                                                        Ranks& ranks) {
  return groundplan::gis::run_pipeline_tiled(options, ranks, ranks.rank() == 0 ? progress : groundplan::Progress{},
                                             groundplan::gis::FinalPlans::kept_by_each_rank);
}

}  // namespace

int run_tiled_into_database(const PipelineOptions& options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                            const Progress& progress, Ranks& ranks) {
  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  const bool root = ranks.rank() == 0;
  std::shared_ptr<const groundplan::gis::TiledResult> result = tiled_kept_by_each_rank(options, progress, ranks);
  const groundplan::gis::TiledResult& r = *result;
  const std::size_t plans = r.tiles.final_plans + r.tiles.reduced_plans;  // rank 0: over all ranks
  output::TableSetup setup;
  setup.dst = ogr.dst;
  setup.options = ogr.options;
  if (!ogr.layer_named) setup.options.push_back("ground_plans");
  const std::vector<std::string> layers = written_layers(ogr);
  const std::string nln = output::table_name(option_flags(ogr), "");
  for (const std::string& l : layers) setup.tables.push_back(layers.size() == 1 && !nln.empty() ? nln : l);
  if (root && r.footprints == 0) {
    say_nothing_usable(ogr, r.buildings_read, r.problems);
    setup.create = false;
  }
  auto* mine = new groundplan::driver::OGRGroundPlanDataSource(std::string(groundplan::driver::kPrefix) + ogr.src,
                                                               result, 0, options.threads);
  auto* empty = new groundplan::driver::OGRGroundPlanDataSource(
      std::string(groundplan::driver::kPrefix) + ogr.src, std::make_shared<const NoPlans>(r), 0, options.threads);
  const output::RankWrite w = output::write_from_every_rank(
      ranks, setup, mine, empty, [&ranks] { ranks.test_point("commit"); });
  if (!root) return w.ok ? 0 : 1;
  if (!ogr.quiet)
    for (const std::string& s : w.left_over)
      std::fprintf(stderr, "groundplan: warning: the database holds the staging schema of another run: %s\n", s.c_str());
  for (const std::string& s : w.warnings) std::fprintf(stderr, "groundplan: warning: %s\n", s.c_str());
  if (!setup.create) {
    write_tiled_stats(stats_path, r, 0, 0, 0, nullptr, seconds_since(t0), groundplan::gis::process_cpu_seconds() - cpu0);
    return 1;
  }
  if (!w.ok) {
    std::fprintf(stderr, "groundplan: could not write %s: %s\n", ogr.dst.c_str(), w.why.c_str());
    return 1;
  }
  WriteOutcome wo;  // --stats "writer": where the tables were made before they went into the user's schema
  wo.ok = true;
  wo.writer = {{"writers", ranks.size()}, {"every_rank_writes", true}};
  if (w.in_place.empty()) wo.writer["staging_schema"] = w.staging_schema;
  else wo.writer["tables_made_in_place"] = w.in_place;
  const int rc = write_tiled_stats(stats_path, r, plans, w.write_s, 0, &wo, seconds_since(t0),
                                   groundplan::gis::process_cpu_seconds() - cpu0) ? 0 : 1;
  if (!ogr.quiet) print_tiled_summary(r, ogr, ogr.dst + " (every rank its own plans)", plans, seconds_since(t0), w.write_s);
  return rc;
}

std::string why_rank_0_writes(const Ogr2ogrArgs& ogr, Ranks& ranks) {
  namespace fs = std::filesystem;
  std::string said, marker;
  if (ranks.rank() == 0) {
    std::string why = packs_gpkg_index(ogr) ? output::slices_ruled_out(option_flags(ogr), written_layers(ogr),
                                                                                "ground_plans")
                                            : "not a new local GeoPackage whose spatial index the CLI packs";
    std::string token;
    if (why.empty()) {
      const fs::path dst(ogr.dst);
      marker = ((dst.has_parent_path() ? dst.parent_path() : fs::path(".")) /
                (".groundplan-shared-" + std::to_string(::getpid())))
                   .string();
      token = std::to_string(::getpid()) + "-" + std::to_string(clock::now().time_since_epoch().count());
      std::ofstream f(marker);
      f << token;
      f.close();
      if (!f) why = "cannot write beside " + ogr.dst;
    }
    said = why.empty() ? marker + "\n" + token : "!" + why;
  }
  said = ranks.broadcast(said);
  int sees = 1;
  if (ranks.rank() != 0 && !said.empty() && said[0] != '!') {
    const std::size_t nl = said.find('\n');
    std::ifstream f(said.substr(0, nl));
    std::string got;
    std::getline(f, got);
    sees = f.is_open() && got == said.substr(nl + 1) && !ranks.test_pretends("shared");
  }
  const std::vector<int> all = ranks.every_rank(sees);
  if (!marker.empty()) {
    std::error_code ec;
    fs::remove(marker, ec);
  }
  if (said.empty() || said[0] == '!') return said.empty() ? std::string("rank 0 said nothing") : said.substr(1);
  std::string blind;
  for (std::size_t r = 0; r < all.size(); ++r)
    if (!all[r]) blind += (blind.empty() ? "" : ", ") + std::to_string(r);
  if (!blind.empty())
    return "the destination's folder is not seen by rank " + blind + " (not a file system every rank shares)";
  return {};
}

int run_tiled_gpkg_by_ranks(const PipelineOptions& options, const Ogr2ogrArgs& ogr, const std::string& stats_path,
                            const Progress& progress, Ranks& ranks) {
  const double cpu0 = groundplan::gis::process_cpu_seconds();
  const auto t0 = clock::now();
  const bool root = ranks.rank() == 0;
  std::shared_ptr<const groundplan::gis::TiledResult> result = tiled_kept_by_each_rank(options, progress, ranks);
  const groundplan::gis::TiledResult& r = *result;
  const std::size_t plans = r.tiles.final_plans + r.tiles.reduced_plans;  // rank 0: over all ranks
  std::unique_ptr<output::StagedOutput> staged;
  output::RankGpkgWrite w;
  w.flags = option_flags(ogr);
  w.flags.insert(w.flags.end(), {"-lco", "SPATIAL_INDEX=NO"});  // packed once the slices are in (gpkg_rtree.h)
  w.layers = written_layers(ogr);
  w.progress = ogr.progress && !ogr.quiet;
  if (root) {
    staged = std::make_unique<output::StagedOutput>(ogr.dst);
    w.dst = staged->path();
    const std::filesystem::path dst(w.dst);
    w.folder = dst.has_parent_path() ? dst.parent_path().string() : ".";
    if (r.footprints == 0) {
      say_nothing_usable(ogr, r.buildings_read, r.problems);
      w.nothing = true;
    }
  }
  const std::string ds_name = std::string(groundplan::driver::kPrefix) + ogr.src;
  const auto t_write = clock::now();
  const output::RankGpkgOutcome o = output::write_gpkg_from_every_rank(
      ranks, w, r,
      [&] {
        return GDALDataset::ToHandle(new groundplan::driver::OGRGroundPlanDataSource(ds_name, result, 0, options.threads));
      },
      vector_translate, [&ranks] { ranks.test_point("slice"); });
  if (!root) {
    ranks.barrier();  // rank 0 has appended the slices
    return 0;
  }
  // Every rank waits for rank 0 here before the dataset is moved into place; rank 0's outcome is its return code.
  auto finish = [&](int rc) {
    ranks.barrier();
    if (rc == 0) staged->commit();
    return rc;
  };
  auto stats = [&](std::size_t n, double write_s, double index_s, const WriteOutcome* written) {
    return write_tiled_stats(stats_path, r, n, write_s, index_s, written, seconds_since(t0),
                             groundplan::gis::process_cpu_seconds() - cpu0);
  };
  if (o.nothing) {
    stats(0, 0, 0, nullptr);
    return finish(1);
  }
  if (!o.ok) {
    std::fprintf(stderr, "groundplan: could not write %s%s: %s\n", ogr.dst.c_str(),
                 o.usage_error ? " (bad ogr2ogr options)" : "", o.why.c_str());
    return finish(1);
  }
  WriteOutcome wo;
  wo.ok = wo.own_index = true;
  const auto t_index = clock::now();
  const bool indexed = output::index_new_gpkg(
      w.dst, static_cast<int>(groundplan::gis::thread_count(options.threads)), wo.built);
  if (wo.built.by_gdal)
    std::fprintf(stderr, "groundplan: note: packing the spatial index failed (%s); GDAL built it instead\n",
                 wo.built.error.c_str());
  if (!indexed) std::fprintf(stderr, "groundplan: warning: %s has no spatial index\n", ogr.dst.c_str());
  wo.index_s = seconds_since(t_index);
  wo.write_s = seconds_since(t_write);
  wo.writer = {{"writers", ranks.size()}, {"by", "every rank, a slice each"}, {"slice_s", o.slice_s},
               {"append_s", o.append_s}};
  const int rc = finish(stats(plans, wo.write_s, wo.index_s, &wo) ? 0 : 1);
  if (!ogr.quiet) print_tiled_summary(r, ogr, ogr.dst, plans, seconds_since(t0), wo.write_s);
  return rc;
}

}  // namespace groundplan::cli

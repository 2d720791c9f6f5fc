// SPDX-License-Identifier: MIT
#include "write_output.h"

#include "csv_slices.h"
#include "gpkg_slices.h"
#include "timing.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal_utils.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace groundplan::cli {
namespace {

using gis::PipelineOptions;

/// The slices' source over the one-process result: a dataset from `another` (on `threads` threads) serving the plans
/// [first, last); null where it cannot be made, and that slice fails, and so the write (gpkg_slices.h).
output::SliceSource slice_source(const AnotherDataset& another, int threads) {
  return [&another, threads](std::size_t first, std::size_t last) -> GDALDatasetH {
    auto* d = another(threads);
    if (!d || !d->layer("ground_plans")) {
      delete d;
      return nullptr;
    }
    d->layer("ground_plans")->restrict_to(first, last);
    return GDALDataset::ToHandle(d);
  };
}

}  // namespace

bool vector_translate(const std::string& dst, GDALDatasetH src, const std::vector<std::string>& args, bool progress,
                      int* usage_error) {
  CPLStringList argv;
  for (const auto& a : args) argv.AddString(a.c_str());
  GDALVectorTranslateOptions* vt = GDALVectorTranslateOptionsNew(argv.List(), nullptr);
  if (!vt) {
    *usage_error = TRUE;
    return false;
  }
  if (progress) GDALVectorTranslateOptionsSetProgress(vt, GDALTermProgress, nullptr);
  GDALDatasetH out = GDALVectorTranslate(dst.c_str(), nullptr, 1, &src, vt, usage_error);
  GDALVectorTranslateOptionsFree(vt);
  if (!out) return false;
  // Closing flushes: an error here (disk full ...) is a failure too.
  CPLErrorReset();
  GDALClose(out);
  return CPLGetLastErrorType() < CE_Failure;
}

std::unique_ptr<output::StreamedGpkg> stream_plans(const Ogr2ogrArgs& ogr, const PipelineOptions& options,
                                                            std::size_t id_chars) {
  if (!CPLTestBool(CPLGetConfigOption("GROUNDPLAN_WRITE_DURING_UNION", "YES"))) return nullptr;
  if (!packs_gpkg_index(ogr) || options.detail.any()) return nullptr;
  const int threads = static_cast<int>(groundplan::gis::thread_count(options.threads));
  if (threads < 2) return nullptr;
  output::StreamedGpkg::Setup setup;
  setup.write.dst = ogr.dst;
  setup.write.flags = option_flags(ogr);
  setup.write.flags.insert(setup.write.flags.end(), {"-lco", "SPATIAL_INDEX=NO"});  // packed afterwards, as write_output
  setup.write.layers = written_layers(ogr);
  if (!output::slices_ruled_out(setup.write.flags, setup.write.layers, "ground_plans").empty()) return nullptr;
  setup.write.progress = ogr.progress && !ogr.quiet;
  setup.threads = threads;
  setup.id_chars = id_chars;
  setup.translate = vector_translate;
  return std::make_unique<output::StreamedGpkg>(std::move(setup));
}

WriteOutcome write_output(groundplan::driver::OGRGroundPlanDataSource* ds, const Ogr2ogrArgs& ogr, int threads,
                          const AnotherDataset& another, output::StreamedGpkg* streamed) {
  WriteOutcome w;
  const bool dbf = writes_dbf(ogr);
  GDALDatasetH src_h = GDALDataset::ToHandle(ds);
  // Streamed, the destination exists by now: it is the new GeoPackage the index is packed for.
  const bool own_index = (streamed && streamed->engaged()) || packs_gpkg_index(ogr);
  w.own_index = own_index;
  std::vector<std::string> flags = option_flags(ogr);
  if (own_index) flags.insert(flags.end(), {"-lco", "SPATIAL_INDEX=NO"});
  const std::vector<std::string> layers = written_layers(ogr);
  std::vector<std::string> vt_args = flags;
  vt_args.insert(vt_args.end(), layers.begin(), layers.end());
  const auto t_write = clock::now();
  int usage_error = FALSE;
  bool write_ok = false;
  const int n_threads = static_cast<int>(groundplan::gis::thread_count(threads));
  std::string why_one = "not a new GeoPackage or CSV file";
  int writers = 1;
  // A new GeoPackage or CSV file: the plans written by several writers side by side (gpkg_slices.h, csv_slices.h).
  std::error_code exists_ec;
  const bool csv = !own_index && output::is_csv_file(ogr.format, ogr.dst) &&
                   !std::filesystem::exists(ogr.dst, exists_ec);
  if (streamed && streamed->engaged() && another) {
    // The slices were written while the union went on (streamed_gpkg.h): slice 0 where it carries other layers,
    // then what is left of the writing and appending.
    writers = 0;
    const auto out = streamed->finish(slice_source(another, std::max(1, n_threads / streamed->writers())));
    write_ok = out.ok;
    if (!out.ok) std::fprintf(stderr, "groundplan: %s\n", out.error.c_str());
    w.writer = {{"writers", streamed->writers()},
                {"during_union", true},
                {"slices", streamed->slices()},
                {"slices_started_during_union", streamed->slices_before_end()},
                {"slices_s", out.slices_s},
                {"after_union_s", out.merge_s}};
  } else if ((own_index || csv) && another) {
    auto* plans_layer = ds->layer("ground_plans");
    const std::size_t plans = plans_layer ? static_cast<std::size_t>(plans_layer->GetFeatureCount(TRUE)) : 0;
    writers = csv ? output::csv_writers(flags, layers, "ground_plans", plans, n_threads, &why_one)
                  : output::gpkg_writers(flags, layers, "ground_plans", plans, n_threads, &why_one);
    if (writers > 1) {
      output::SliceWrite sw;
      sw.dst = ogr.dst;
      sw.flags = flags;
      sw.layers = layers;
      sw.plans = plans;
      sw.writers = writers;
      sw.progress = ogr.progress && !ogr.quiet;
      const output::SliceSource source = slice_source(another, std::max(1, n_threads / writers));
      const auto slice = csv ? output::write_csv_slices(sw, source, vector_translate)
                             : output::write_gpkg_slices(sw, source, vector_translate);
      write_ok = slice.ok;
      usage_error = slice.usage_error;
      if (!slice.ok) std::fprintf(stderr, "groundplan: %s\n", slice.error.c_str());
      w.writer = {{"writers", writers}, {"slices_s", slice.slices_s}, {"append_s", slice.merge_s}};
    }
  }
  if (writers == 1) {
    write_ok = vector_translate(ogr.dst, src_h, vt_args, ogr.progress && !ogr.quiet, &usage_error);
    w.writer = {{"writers", 1}, {"why_one", why_one}};
  }
  double index_s = 0;
  output::RtreeBuild& built = w.built;
  if (write_ok && own_index) {
    const auto t_index = clock::now();
    const bool indexed = output::index_new_gpkg(
        ogr.dst, static_cast<int>(groundplan::gis::thread_count(threads)), built);
    if (built.by_gdal)
      std::fprintf(stderr, "groundplan: note: packing the spatial index failed (%s); GDAL built it instead\n",
                   built.error.c_str());
    if (!indexed) std::fprintf(stderr, "groundplan: warning: %s has no spatial index\n", ogr.dst.c_str());
    index_s = seconds_since(t_index);
  }
  // DBF fields hold 254 characters: cut lists are marked "...(+N)" and the full lists go beside them.
  std::string& members_note = w.members_note;
  const bool members_named =
      std::find(ogr.layers.begin(), ogr.layers.end(), std::string("plan_members")) != ogr.layers.end();
  if (write_ok && dbf && ds->id_lists_cut() && !members_named) {
    std::filesystem::path dst(ogr.dst);
    const bool single_file = lower(dst.extension().string()) == ".shp";
    const std::string dir = single_file ? (dst.has_parent_path() ? dst.parent_path().string() : ".") : ogr.dst;
    const std::string name = (single_file ? dst.stem().string() : std::string("ground_plans")) + "_members";
    std::vector<std::string> args = {"-f", "ESRI Shapefile", "-nln", name, "plan_members"};
    if (std::find(ogr.options.begin(), ogr.options.end(), "-overwrite") != ogr.options.end())
      args.insert(args.begin(), "-overwrite");
    write_ok = vector_translate(dir, src_h, args, false, &usage_error);
    members_note = std::to_string(ds->id_lists_cut()) +
                   " plans list more building ids than a DBF field holds (254 characters): their building_ids end "
                   "in '...(+N)'; the full lists are in " +
                   (std::filesystem::path(dir) / (name + ".dbf")).string() + " (gp_id, fp_id, source_id, bldg_id)";
  }
  GDALClose(src_h);
  w.ok = write_ok;
  w.usage_error = usage_error;
  w.write_s = seconds_since(t_write);
  w.index_s = index_s;
  return w;
}

}  // namespace groundplan::cli

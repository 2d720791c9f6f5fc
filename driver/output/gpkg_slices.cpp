// SPDX-License-Identifier: MIT
#include "gpkg_slices.h"

#include "sqlite_db.h"

#include <cpl_port.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <set>
#include <thread>
#include <unistd.h>

namespace groundplan::output {
namespace {

// Plans a writer at least: below this, a second GDAL writer costs more than it saves.
constexpr std::size_t kPlansPerWriter = 8192;
// Writers at most: past this the appending (serial) is most of the time.
constexpr int kMaxWriters = 16;

/// The ogr2ogr options that act on each feature alone (so a slice of the features gives a slice of the
/// output), with how many values follow them. Anything else (-where on our FIDs, -sql, -limit, -fid,
/// -explodecollections, -preserve_fid, -unsetFid, -append ...) keeps one writer.
int per_feature_arity(const std::string& opt) {
  static const std::set<std::string> none = {"-progress", "-q", "-quiet", "-overwrite", "-skipfailures"};
  static const std::set<std::string> one = {"-f", "-of", "-lco", "-dsco", "-nln", "-nlt", "-t_srs", "-a_srs", "-gt"};
  if (none.count(opt)) return 0;
  if (one.count(opt)) return 1;
  if (opt == "--config") return 2;
  return -1;
}

/// Appends the rows of the attached `part`'s table with rowids in [first, last] (all of them where last < first)
/// to the destination's (same schema, FIDs kept) and widens the destination's extent by the part's.
void append_part(const sqlite::Db& db, const std::string& part, const std::string& table, std::int64_t first,
                 std::int64_t last) {
  using sqlite::id;
  using sqlite::lit;
  auto columns = [&](const std::string& schema) {
    std::vector<std::string> cols;
    sqlite::Stmt s(db, "PRAGMA " + schema + ".table_info(" + id(table) + ")");
    while (s.row()) cols.push_back(s.text(1) + " " + s.text(2) + " " + s.text(3) + " " + s.text(5));
    return cols;
  };
  const std::vector<std::string> dst_columns = columns("main");
  if (dst_columns.empty() || columns("part") != dst_columns)
    throw sqlite::Failure(part + ": the slice's table " + table + " is not the destination's");
  std::string rows = "INSERT INTO main." + id(table) + " SELECT * FROM part." + id(table);
  // GeoPackage tables have an INTEGER PRIMARY KEY (the FID): rowid is that column whatever its name.
  if (first <= last) rows += " WHERE rowid BETWEEN " + std::to_string(first) + " AND " + std::to_string(last);
  db.exec(rows);
  // gpkg_contents: the extent of all slices (min/max skip the NULLs of a slice without geometry).
  std::string set;
  for (const char* c : {"min_x", "min_y", "max_x", "max_y"}) {
    const std::string agg = c[1] == 'i' ? "min" : "max";
    set += std::string(set.empty() ? "" : ", ") + c + " = (SELECT " + agg + "(v) FROM (SELECT main.gpkg_contents." + c +
           " AS v UNION ALL SELECT " + c + " FROM part.gpkg_contents WHERE lower(table_name) = lower(" + lit(table) +
           ")))";
  }
  db.exec("UPDATE main.gpkg_contents SET " + set + " WHERE lower(table_name) = lower(" + lit(table) + ")");
}

}  // namespace

Appender::Appender(const std::string& dst, const std::vector<std::string>& tables) : db_(dst), tables_(tables) {
  using sqlite::lit;
  for (const std::string& table : tables_) {
    sqlite::Stmt s(db_, "SELECT name, sql FROM sqlite_master WHERE type = 'trigger' AND lower(tbl_name) = lower(" +
                            lit(table) + ")");
    while (s.row()) triggers_.push_back({s.text(0), s.text(1)});
  }
  {
    sqlite::Stmt s(db_, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'gpkg_ogr_contents'");
    has_ogr_contents_ = s.row();
  }
  // The file is only handed over after the last commit, which syncs it; the appends need not each.
  db_.exec("PRAGMA synchronous = OFF");
  for (const auto& t : triggers_) db_.exec("DROP TRIGGER " + sqlite::id(t[0]));
}

void Appender::append(const AppendRun& run) {
  if (std::find(tables_.begin(), tables_.end(), run.table) == tables_.end())
    throw sqlite::Failure(run.table + ": not a table this appender was opened for");
  db_.exec("ATTACH DATABASE " + sqlite::lit(run.part) + " AS part");
  try {
    db_.exec("BEGIN");
    append_part(db_, run.part, run.table, run.first, run.last);
    db_.exec("COMMIT");
  } catch (...) {
    db_.exec("ROLLBACK");
    db_.exec("DETACH DATABASE part");
    throw;
  }
  db_.exec("DETACH DATABASE part");
}

void Appender::finish() {
  using sqlite::id;
  using sqlite::lit;
  db_.exec("PRAGMA synchronous = FULL");
  db_.exec("BEGIN");
  if (has_ogr_contents_)
    for (const std::string& table : tables_)
      db_.exec("UPDATE gpkg_ogr_contents SET feature_count = (SELECT count(*) FROM " + id(table) +
               ") WHERE lower(table_name) = lower(" + lit(table) + ")");
  for (const auto& t : triggers_) db_.exec(t[1]);
  db_.exec("COMMIT");
}

void append_runs(const std::string& dst, const std::vector<AppendRun>& runs) {
  std::vector<std::string> tables;
  for (const AppendRun& r : runs)
    if (std::find(tables.begin(), tables.end(), r.table) == tables.end()) tables.push_back(r.table);
  Appender appender(dst, tables);
  for (const AppendRun& run : runs) appender.append(run);
  appender.finish();
}

void remove_with_sidecars(const std::string& path) {
  std::error_code ec;
  for (const char* suffix : {"", "-journal", "-wal", "-shm"}) std::filesystem::remove(path + suffix, ec);
}

std::string table_name(const std::vector<std::string>& flags, const std::string& plans_layer) {
  std::string name = plans_layer;
  for (std::size_t i = 0; i + 1 < flags.size(); ++i)
    if (flags[i] == "-nln") name = flags[i + 1];
  return name;
}

std::string slices_ruled_out(const std::vector<std::string>& flags, const std::vector<std::string>& layers,
                             const std::string& plans_layer) {
  if (std::none_of(layers.begin(), layers.end(), [&](const std::string& l) { return EQUAL(l.c_str(), plans_layer.c_str()); }))
    return "the " + plans_layer + " layer is not written";
  for (std::size_t i = 0; i < flags.size(); ++i) {
    const int n = per_feature_arity(flags[i]);
    if (n < 0) return "ogr2ogr option " + flags[i];
    if (flags[i] == "-nln" && layers.size() > 1) return "-nln with several layers";
    i += static_cast<std::size_t>(n);
  }
  return {};
}

void sqlite_without_memory_statistics() { sqlite3_config(SQLITE_CONFIG_MEMSTATUS, 0); }

int writers_for(std::size_t plans, int threads, std::string* why_one) {
  const int by_plans = static_cast<int>(std::min<std::size_t>(plans / kPlansPerWriter, kMaxWriters));
  const int writers = std::min(threads, by_plans);
  if (writers >= 2) return writers;
  if (why_one) *why_one = threads < 2 ? "one thread" : "fewer than " + std::to_string(2 * kPlansPerWriter) + " plans";
  return 1;
}

int gpkg_writers(const std::vector<std::string>& flags, const std::vector<std::string>& layers,
                 const std::string& plans_layer, std::size_t plans, int threads, std::string* why_one) {
  const int writers = writers_for(plans, threads, why_one);
  if (writers < 2) return 1;
  std::string why = slices_ruled_out(flags, layers, plans_layer);
  if (!why.empty()) {
    if (why_one) *why_one = std::move(why);
    return 1;
  }
  return writers;
}

std::string slice_path(const std::string& dst, std::size_t k, const std::string& ext) {
  if (k == 0) return dst;
  const std::filesystem::path d(dst);
  return (d.parent_path() / ("." + d.stem().string() + ".slice" + std::to_string(k) + "-" + std::to_string(::getpid()) +
                             ext))
      .string();
}

std::vector<std::string> slice_paths(const std::string& dst, int writers, const std::string& ext) {
  std::vector<std::string> paths;
  for (int k = 0; k < std::max(1, writers); ++k) paths.push_back(slice_path(dst, static_cast<std::size_t>(k), ext));
  return paths;
}

std::size_t slice_start(std::size_t plans, int k, int writers) {
  return plans * static_cast<std::size_t>(k) / static_cast<std::size_t>(writers);
}

bool write_slices_side_by_side(const SliceWrite& w, const SliceSource& source, const Translate& translate,
                               const std::vector<std::string>& paths, const std::vector<std::string>& extra,
                               SliceOutcome& out) {
  using clock = std::chrono::steady_clock;
  const int k_max = static_cast<int>(paths.size());
  const auto t0 = clock::now();
  std::vector<char> ok(paths.size(), 0);
  std::vector<int> usage(paths.size(), 0);
  auto write_slice = [&](int k) {
    GDALDatasetH src = source(slice_start(w.plans, k, k_max), slice_start(w.plans, k + 1, k_max));
    if (!src) return;
    std::vector<std::string> args = w.flags;
    args.insert(args.end(), extra.begin(), extra.end());
    if (k == 0)
      args.insert(args.end(), w.layers.begin(), w.layers.end());
    else
      args.push_back(w.plans_layer);
    int ue = 0;
    ok[static_cast<std::size_t>(k)] = translate(paths[static_cast<std::size_t>(k)], src, args, w.progress && k == 0, &ue);
    usage[static_cast<std::size_t>(k)] = ue;
    GDALClose(src);
  };
  {
    std::vector<std::thread> threads;
    for (int k = 1; k < k_max; ++k) threads.emplace_back(write_slice, k);
    write_slice(0);
    for (auto& t : threads) t.join();
  }
  out.slices_s = std::chrono::duration<double>(clock::now() - t0).count();
  out.usage_error = *std::max_element(usage.begin(), usage.end());
  for (int k = 0; k < k_max; ++k)
    if (!ok[static_cast<std::size_t>(k)]) {
      out.error = "writing slice " + std::to_string(k) + " of the plans failed";
      return false;
    }
  return true;
}

SliceOutcome write_gpkg_slices(const SliceWrite& w, const SliceSource& source, const Translate& translate) {
  using clock = std::chrono::steady_clock;
  SliceOutcome out;
  const int k_max = std::max(1, w.writers);
  const std::vector<std::string> paths = slice_paths(w.dst, k_max, ".gpkg");
  const std::vector<std::string> parts(paths.begin() + 1, paths.end());
  for (const auto& p : parts) remove_with_sidecars(p);
  auto fail = [&](std::string why) {
    out.error = std::move(why);
    for (const auto& p : parts) remove_with_sidecars(p);
    remove_with_sidecars(w.dst);
    return out;
  };
  // The source's FIDs are the plans' indices + 1: slices append in order.
  if (!write_slices_side_by_side(w, source, translate, paths, {"-preserve_fid"}, out)) return fail(out.error);

  const auto t1 = clock::now();
  try {
    std::vector<AppendRun> runs;
    for (const std::string& p : parts) runs.push_back({p, table_name(w.flags, w.plans_layer)});
    append_runs(w.dst, runs);
  } catch (const std::exception& e) {
    return fail(std::string("appending the slices failed: ") + e.what());
  }
  out.merge_s = std::chrono::duration<double>(clock::now() - t1).count();
  for (const auto& p : parts) remove_with_sidecars(p);
  out.ok = true;
  return out;
}

}  // namespace groundplan::output

// SPDX-License-Identifier: MIT
#include "rank_writes.h"

#include "pg_staging.h"

#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal_utils.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>

namespace groundplan::output {
namespace {


double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// "rank R: why; rank S: why" over the ranks that failed; empty when none did.
std::string failures(const std::vector<std::string>& texts) {
  std::string out;
  for (std::size_t r = 0; r < texts.size(); ++r)
    if (!texts[r].empty()) out += (out.empty() ? "rank " : "; rank ") + std::to_string(r) + ": " + texts[r];
  return out;
}

/// GDAL's ogr2ogr from `src` into `dst` (a name, or an open dataset `dst_ds` to add to); empty or why it failed.
std::string ogr2ogr_into(const std::string& dst, GDALDatasetH dst_ds, GDALDataset* src,
                         const std::vector<std::string>& args) {
  CPLStringList argv;
  for (const std::string& a : args) argv.AddString(a.c_str());
  GDALVectorTranslateOptions* vt = GDALVectorTranslateOptionsNew(argv.List(), nullptr);
  if (!vt) return "bad ogr2ogr options";
  GDALDatasetH src_h = GDALDataset::ToHandle(src);
  int usage_error = FALSE;
  CPLErrorReset();
  GDALDatasetH out = GDALVectorTranslate(dst.c_str(), dst_ds, 1, &src_h, vt, &usage_error);
  GDALVectorTranslateOptionsFree(vt);
  if (!out) return gdal_error(usage_error ? "bad ogr2ogr options" : "ogr2ogr failed");
  const bool failed = CPLGetLastErrorType() >= CE_Failure;
  if (!dst_ds) {
    CPLErrorReset();
    GDALClose(out);  // closing flushes (the tables are made here)
    if (CPLGetLastErrorType() >= CE_Failure) return gdal_error("closing failed");
  }
  return failed ? gdal_error("ogr2ogr failed") : std::string();
}

/// The rank's open PostgreSQL datasource as ogr2ogr sees it: the same layers, but the transaction is ours. GDAL's
/// ogr2ogr commits the destination's transaction itself (at the end, and every -gt features; "-gt 0" does not turn
/// that off), which would commit the rank's rows before every rank has written: here its StartTransaction and
/// CommitTransaction do nothing, and the rank commits the real one after the exchange of outcomes.
class HeldTransaction final : public GDALDataset {
 public:
  explicit HeldTransaction(GDALDataset* real) : real_(real) {
    poDriver = real->GetDriver();
    SetDescription(real->GetDescription());
  }
  int GetLayerCount() override { return real_->GetLayerCount(); }
  OGRLayer* GetLayer(int i) override { return real_->GetLayer(i); }
  OGRLayer* GetLayerByName(const char* name) override { return real_->GetLayerByName(name); }
  int TestCapability(const char* cap) override {
    return EQUAL(cap, ODsCTransactions) ? TRUE : real_->TestCapability(cap);
  }
  OGRErr StartTransaction(int) override { return OGRERR_NONE; }
  OGRErr CommitTransaction() override { return OGRERR_NONE; }
  OGRErr RollbackTransaction() override { return OGRERR_NONE; }

 private:
  GDALDataset* real_;
};

/// How long a rank's statement may wait for a lock. The ranks' rows never share a key, so an append waits for
/// nothing; but two uncommitted rows with one key make the second insert wait for the first transaction, which
/// waits (in the exchange of outcomes) for the second rank: a deadlock PostgreSQL cannot see. A timeout turns it
/// into an error every rank learns. Only a fault (ids given twice) gets there.
constexpr const char* kLockTimeout = "60s";

/// SET lock_timeout on the rank's connection; false when the server refuses.
bool wait_for_locks_at_most(GDALDatasetH dst, const char* timeout) {
  CPLErrorReset();
  const std::string sql = std::string("SET lock_timeout = '") + timeout + "'";
  OGRLayerH rs = GDALDatasetExecuteSQL(dst, sql.c_str(), nullptr, nullptr);
  if (rs) GDALDatasetReleaseResultSet(dst, rs);
  return CPLGetLastErrorType() < CE_Failure;
}

/// Which of `tables` exist in the datasource `dst` (names as GDAL gives them); nullopt when it cannot be opened.
std::optional<std::vector<std::string>> existing_tables(const std::string& dst, const CPLStringList& doo,
                                                        const std::vector<std::string>& tables, bool update) {
  const char* const drivers[] = {"PostgreSQL", nullptr};
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDataset* ds = GDALDataset::FromHandle(
      GDALOpenEx(dst.c_str(), GDAL_OF_VECTOR | (update ? GDAL_OF_UPDATE : 0), drivers, doo.List(), nullptr));
  std::optional<std::vector<std::string>> out;
  if (ds) {
    out.emplace();
    for (const std::string& t : tables)
      if (OGRLayer* l = ds->GetLayerByName(t.c_str())) out->push_back(l->GetName());
    GDALClose(GDALDataset::ToHandle(ds));
  }
  CPLPopErrorHandler();
  return out;
}

/// Drops the tables of `tables` that exist now but were not in `before` (made by this run); what it dropped.
std::vector<std::string> drop_made_tables(const std::string& dst, const CPLStringList& doo,
                                          const std::vector<std::string>& tables,
                                          const std::vector<std::string>& before) {
  std::vector<std::string> dropped;
  const char* const drivers[] = {"PostgreSQL", nullptr};
  GDALDataset* ds = GDALDataset::FromHandle(
      GDALOpenEx(dst.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, drivers, doo.List(), nullptr));
  if (!ds) return dropped;
  for (const std::string& t : tables) {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    OGRLayer* l = ds->GetLayerByName(t.c_str());
    CPLPopErrorHandler();
    if (!l) continue;
    const std::string name = l->GetName();
    if (std::any_of(before.begin(), before.end(), [&](const std::string& b) { return EQUAL(b.c_str(), name.c_str()); }))
      continue;
    for (int i = 0; i < ds->GetLayerCount(); ++i)
      if (ds->GetLayer(i) == l) {
        if (ds->DeleteLayer(i) == OGRERR_NONE) dropped.push_back(name);
        break;
      }
  }
  GDALClose(GDALDataset::ToHandle(ds));
  return dropped;
}

/// The -doo NAME=VALUE open options among the user's options.
CPLStringList open_options(const std::vector<std::string>& options) {
  CPLStringList out;
  for (std::size_t i = 0; i + 1 < options.size(); ++i)
    if (options[i] == "-doo") out.AddString(options[i + 1].c_str());
  return out;
}

}  // namespace

bool written_by_every_rank(const std::string& format, const std::string& dst) {
  if (!format.empty()) return EQUAL(format.c_str(), "PostgreSQL");
  return dst.rfind("PG:", 0) == 0 || dst.rfind("pg:", 0) == 0;
}

std::vector<std::string> append_options(const std::vector<std::string>& options, bool own_ids) {
  static const std::set<std::string> drop_with_value = {"-f", "-of", "-lco", "-dsco", "-gt"};
  static const std::set<std::string> drop = {"-overwrite", "-append", "-update", "-ds_transaction",
                                             "-lyr_transaction", "-preserve_fid"};
  std::vector<std::string> out;
  bool preserve = own_ids;
  for (std::size_t i = 0; i < options.size(); ++i) {
    const std::string& o = options[i];
    if (drop_with_value.count(o)) {
      ++i;
      continue;
    }
    if (drop.count(o)) continue;
    if (o == "-unsetFid" || o == "-explodecollections") preserve = false;
    out.push_back(o);
  }
  // before the layer names (ogr2ogr takes the positional arguments wherever they are)
  std::vector<std::string> head = {"-append", "-gt", "unlimited"};
  if (preserve) head.push_back("-preserve_fid");
  out.insert(out.begin(), head.begin(), head.end());
  return out;
}

RankWrite write_from_every_rank(gis::TileExchange& ex, const TableSetup& setup, GDALDataset* mine,
                                GDALDataset* empty_layers, const std::function<void()>& before_commit) {
  const auto t0 = std::chrono::steady_clock::now();
  RankWrite w;

  // 1. Rank 0 makes the tables (with the user's options: -overwrite, -lco ...); the others wait for its word. Where
  // it can, it makes them in a staging schema (pg_staging.h), moved into the user's schema only in step 4. Otherwise
  // it notes which of them were there before: on failure it drops the others (made by this run) again.
  const CPLStringList doo = open_options(setup.options);
  const bool overwrite = std::find(setup.options.begin(), setup.options.end(), "-overwrite") != setup.options.end();
  std::string created;
  std::optional<std::vector<std::string>> before;
  std::optional<PgStaging> staging;
  if (ex.rank() == 0 && setup.create) {
    before = existing_tables(setup.dst, doo, setup.tables, false);
    w.in_place = why_tables_in_place(setup.dst, setup.options, setup.tables, before);
    std::string no_schema;
    if (w.in_place.empty()) staging = make_staging_schema(setup.dst, doo, &no_schema);
    if (w.in_place.empty() && !staging) w.in_place = no_schema;  // e.g. no CREATE right on the database
    if (staging) {
      w.staging_schema = staging->schema;
      w.left_over = staging->found;
    }
  }
  if (ex.rank() == 0)
    created = !setup.create ? std::string("nothing to write")
                            : ogr2ogr_into(staging ? staging->staged_dst() : setup.dst, nullptr, empty_layers,
                                        setup.options);
  GDALClose(GDALDataset::ToHandle(empty_layers));
  // Only a datasource seen before the run tells what it made; one that could not be opened is left alone.
  auto drop_made = [&] {
    if (staging) {
      const std::string why = drop_staging_schema(*staging, doo);
      if (!why.empty()) return "; the staging schema " + staging->schema + " holding this run's tables stays: " + why;
      return "; the tables this run made are dropped (staging schema " + staging->schema + ")";
    }
    if (before) w.dropped = drop_made_tables(setup.dst, doo, setup.tables, *before);
    std::string list;
    for (const std::string& t : w.dropped) list += (list.empty() ? "" : ", ") + t;
    return list.empty() ? std::string() : "; the tables this run made are dropped: " + list;
  };
  const std::string not_created = gather_text(ex, created).at(0);
  if (!not_created.empty()) {
    GDALClose(GDALDataset::ToHandle(mine));
    w.why = "rank 0 could not create the tables: " + not_created;
    if (ex.rank() == 0 && setup.create) w.why += drop_made();
    w.write_s = seconds_since(t0);
    return w;
  }
  // Rank 0's word to every rank, in one exchange: whether a table of the run was there before (its rows' ids could
  // be repeated: the database numbers the new rows instead of gp_id), then where to write (the staging schema's
  // datasource; empty: the user's).
  std::string word;
  if (ex.rank() == 0) word = std::string(!staging && before && !before->empty() ? "x" : "-") +
                             (staging ? staging->staged_dst() : std::string());
  word = gather_text(ex, word).at(0);
  const bool own_ids = word.rfind('x', 0) != 0;
  const std::string write_dst = word.size() > 1 ? word.substr(1) : std::string();

  // 2. Every rank adds its share in one transaction of its own, not committed yet.
  std::string wrote;
  const char* const drivers[] = {"PostgreSQL", nullptr};
  CPLErrorReset();
  const std::string& into = write_dst.empty() ? setup.dst : write_dst;
  GDALDatasetH dst = GDALOpenEx(into.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE | GDAL_OF_VERBOSE_ERROR, drivers,
                                doo.List(), nullptr);
  bool in_transaction = false;
  if (!dst) {
    wrote = "cannot open " + into + ": " + gdal_error("no PostgreSQL datasource");
  } else if (!wait_for_locks_at_most(dst, kLockTimeout)) {
    wrote = "cannot set lock_timeout: " + gdal_error("the server refused");
  } else if (GDALDatasetStartTransaction(dst, FALSE) != OGRERR_NONE) {
    wrote = "cannot start a transaction: " + gdal_error("the driver refused");
  } else {
    in_transaction = true;
    HeldTransaction held(GDALDataset::FromHandle(dst));
    wrote = ogr2ogr_into(into, GDALDataset::ToHandle(&held), mine, append_options(setup.options, own_ids));
  }
  GDALClose(GDALDataset::ToHandle(mine));
  // A rank that throws here (a fault, or the test hook) is a rank that failed to write: every rank rolls back.
  try {
    if (before_commit) before_commit();
  } catch (const std::exception& e) {
    if (wrote.empty()) wrote = e.what();
  }

  // 3. Commit only once every rank has written all of its rows; otherwise every rank rolls back.
  const std::string not_written = failures(gather_text(ex, wrote));
  std::string committed;
  if (in_transaction) {
    CPLErrorReset();
    const OGRErr e = not_written.empty() ? GDALDatasetCommitTransaction(dst) : GDALDatasetRollbackTransaction(dst);
    if (e != OGRERR_NONE) committed = (not_written.empty() ? "commit failed: " : "rollback failed: ") + gdal_error("");
  }
  if (dst) {
    CPLErrorReset();
    GDALClose(dst);
    if (committed.empty() && CPLGetLastErrorType() >= CE_Failure) committed = "closing failed: " + gdal_error("");
  }
  const std::string not_committed = failures(gather_text(ex, committed));
  w.write_s = seconds_since(t0);
  if (!not_written.empty()) {
    w.why = not_written + " (every rank rolled back: none of this run's rows are in the tables)";
    if (ex.rank() == 0) w.why += drop_made();
    return w;
  }
  if (!not_committed.empty()) {
    w.why = not_committed + (staging ? " (the other ranks' rows were committed in the staging schema only)"
                                      : " (the other ranks' rows are committed: the tables are incomplete)");
    if (ex.rank() == 0) w.why += drop_made();
    return w;
  }
  // 4. Every rank has closed its connection (before the last exchange): rank 0 sets the id sequences past every
  // rank's rows, then moves the staged tables into the user's schema, in one transaction (replacing the old ones
  // under -overwrite): only now does the user's schema hold anything of the run.
  if (ex.rank() == 0) {
    const std::string why = staging ? advance_id_sequences(staging->staged_dst(), doo, setup.tables, staging->schema)
                                    : advance_id_sequences(setup.dst, doo, setup.tables, "");
    if (!why.empty() && !staging)
      w.warnings.push_back("the rows are committed, but the id sequences may be behind them: " + why);
    if (!why.empty() && staging) {
      w.write_s = seconds_since(t0);
      w.why = "cannot set the id sequences in the staging schema " + staging->schema + ": " + why + drop_made();
      return w;
    }
  }
  if (ex.rank() == 0 && staging) {
    const std::string why = move_staged_tables(*staging, doo, overwrite);
    w.write_s = seconds_since(t0);
    if (!why.empty()) {
      w.why = "cannot move the tables from the staging schema " + staging->schema + " into " + staging->target +
              ": " + why + " (schema " + staging->target + " is as it was)" + drop_made();
      return w;
    }
  }
  w.ok = true;
  return w;
}

/// Every rank's `text` (empty: all went well), in rank order.
std::vector<std::string> gather_text(gis::TileExchange& ex, const std::string& text) {
  std::vector<std::uint64_t> sizes;
  const std::vector<char> all = ex.allgather(std::vector<char>(text.begin(), text.end()), &sizes);
  std::vector<std::string> out;
  std::size_t at = 0;
  for (std::uint64_t n : sizes) {
    out.emplace_back(all.data() + at, static_cast<std::size_t>(n));
    at += static_cast<std::size_t>(n);
  }
  return out;
}

}  // namespace groundplan::output

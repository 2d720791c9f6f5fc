// SPDX-License-Identifier: MIT
#include "gpkg_rank_slices.h"

#include "rank_writes.h"
#include "sqlite_db.h"

#include <cpl_error.h>
#include <cpl_port.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>
#include <unistd.h>

namespace groundplan::output {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void add_run(std::vector<FidRun>& runs, std::uint64_t first, std::uint64_t count) {
  if (count == 0) return;
  if (!runs.empty() && runs.back().last + 1 == first)
    runs.back().last += count;
  else
    runs.push_back({first, first + count - 1});
}

bool is_layer(const std::string& a, const char* b) { return EQUAL(a.c_str(), b); }

// What a rank says after writing its slice: "p FIRST LAST" and "m FIRST LAST" lines, or "!why".
std::string runs_text(const std::vector<FidRun>& plans, const std::vector<FidRun>& members) {
  std::string out;
  for (const FidRun& r : plans) out += "p " + std::to_string(r.first) + " " + std::to_string(r.last) + "\n";
  for (const FidRun& r : members) out += "m " + std::to_string(r.first) + " " + std::to_string(r.last) + "\n";
  return out;
}

struct RankRun {
  int rank = 0;
  FidRun fids;
};

/// The runs every rank holds of one kind ('p' or 'm'), in FID order; throws when together they are not the FIDs
/// 1..N each once (a fault of the numbering).
std::vector<RankRun> ordered_runs(const std::vector<std::string>& texts, char kind, std::uint64_t* total) {
  std::vector<RankRun> out;
  for (std::size_t r = 0; r < texts.size(); ++r) {
    std::istringstream in(texts[r]);
    char k = 0;
    std::uint64_t first = 0, last = 0;
    while (in >> k >> first >> last)
      if (k == kind) out.push_back({static_cast<int>(r), {first, last}});
  }
  std::sort(out.begin(), out.end(), [](const RankRun& a, const RankRun& b) { return a.fids.first < b.fids.first; });
  std::uint64_t next = 1;
  for (const RankRun& r : out) {
    if (r.fids.first != next || r.fids.last < r.fids.first)
      throw sqlite::Failure(std::string("the ranks' ") + (kind == 'p' ? "plans" : "plan_members rows") +
                            " do not number 1..N once each (rank " + std::to_string(r.rank) + " has FIDs " +
                            std::to_string(r.fids.first) + ".." + std::to_string(r.fids.last) + ")");
    next = r.fids.last + 1;
  }
  *total = next - 1;
  return out;
}

/// Rows, smallest and largest FID of `table` in `dst`: the whole run has to be there, once.
void check_rows(const std::string& dst, const std::string& table, std::uint64_t total) {
  sqlite::Db db(dst, SQLITE_OPEN_READONLY);
  sqlite::Stmt s(db, "SELECT count(*), coalesce(min(rowid), 0), coalesce(max(rowid), 0) FROM " + sqlite::id(table));
  s.row();
  const auto n = static_cast<std::uint64_t>(sqlite3_column_int64(s.get(), 0));
  const auto lo = static_cast<std::uint64_t>(sqlite3_column_int64(s.get(), 1));
  const auto hi = static_cast<std::uint64_t>(sqlite3_column_int64(s.get(), 2));
  if (n != total || (total > 0 && (lo != 1 || hi != total)))
    throw sqlite::Failure(table + " has " + std::to_string(n) + " rows (FIDs " + std::to_string(lo) + ".." +
                          std::to_string(hi) + ") after the append, not " + std::to_string(total));
}

}  // namespace

std::vector<FidRun> plan_runs(const gis::TiledResult& mine) {
  std::vector<FidRun> runs;
  for (std::size_t i = 0; i < mine.plan_count(); ++i) add_run(runs, mine.plan_number(i) + 1, 1);
  return runs;
}

std::vector<FidRun> member_runs(const gis::TiledResult& mine) {
  std::vector<FidRun> runs;
  for (std::size_t i = 0; i < mine.plan_count(); ++i)
    add_run(runs, mine.row_number(i) + 1, mine.members_before(i + 1) - mine.members_before(i));
  return runs;
}

RankGpkgOutcome write_gpkg_from_every_rank(gis::TileExchange& ex, const RankGpkgWrite& w, const gis::TiledResult& mine,
                                           const std::function<GDALDatasetH()>& dataset, const Translate& translate,
                                           const std::function<void()>& after_slice) {
  RankGpkgOutcome out;
  const bool root = ex.rank() == 0;

  // 1. Rank 0 names the folder of the slices, an id of the run and the destination's name ("!": nothing to write).
  std::string head;
  if (root)
    head = w.nothing ? std::string("!")
                     : w.folder + "\n" + std::to_string(::getpid()) + "\n" + std::filesystem::path(w.dst).stem().string();
  head = gather_text(ex, head).at(0);
  if (head == "!") {
    out.nothing = true;
    return out;
  }
  std::vector<std::string> h;
  {
    std::istringstream in(head);
    for (std::string line; std::getline(in, line);) h.push_back(line);
  }
  if (h.size() != 3) throw sqlite::Failure("rank 0 sent a malformed slice header");
  auto slice_of = [&](int r) {
    return (std::filesystem::path(h[0]) / ("." + h[2] + ".rank" + std::to_string(r) + "-" + h[1] + ".gpkg")).string();
  };
  const std::string mine_path = root ? w.dst : slice_of(ex.rank());

  // 2. Every rank writes its slice side by side: rank 0 the destination with every layer asked for, the others
  // their plans and members, each feature with the FID it has in the one dataset.
  const std::string plans_table = table_name(w.flags, "ground_plans");
  const bool with_members =
      std::any_of(w.layers.begin(), w.layers.end(), [](const std::string& l) { return is_layer(l, "plan_members"); });
  std::vector<std::string> args = w.flags;
  args.push_back("-preserve_fid");
  for (const std::string& l : w.layers)
    if (root || is_layer(l, "ground_plans") || is_layer(l, "plan_members")) args.push_back(l);
  const auto t0 = std::chrono::steady_clock::now();
  std::string wrote;
  try {
    if (!root) remove_with_sidecars(mine_path);
    GDALDatasetH src = dataset();
    if (!src) throw sqlite::Failure("no dataset of its plans");
    CPLErrorReset();
    int ue = 0;
    const bool ok = translate(mine_path, src, args, w.progress && root, &ue);
    GDALClose(src);
    out.usage_error = ue;
    if (!ok) {
      const char* m = CPLGetLastErrorMsg();
      wrote = "writing " + mine_path + " failed" + (m && *m ? std::string(": ") + m : std::string());
    }
    if (wrote.empty() && after_slice) after_slice();
  } catch (const std::exception& e) {
    wrote = e.what();
  }
  out.slice_s = seconds_since(t0);
  for (char& c : wrote)
    if (c == '\n') c = ' ';
  const std::string said = wrote.empty() ? runs_text(plan_runs(mine), with_members ? member_runs(mine) : std::vector<FidRun>{})
                                         : "!" + wrote;

  // 3. Every rank's outcome; rank 0 appends the slices' rows in FID order, or every file goes.
  const std::vector<std::string> texts = gather_text(ex, said);
  std::string failed;
  for (std::size_t r = 0; r < texts.size(); ++r)
    if (!texts[r].empty() && texts[r][0] == '!')
      failed += (failed.empty() ? "rank " : "; rank ") + std::to_string(r) + ": " + texts[r].substr(1);
  auto remove_all = [&] {
    if (!root) return;
    remove_with_sidecars(w.dst);
    for (int r = 1; r < ex.size(); ++r) remove_with_sidecars(slice_of(r));
  };
  if (!failed.empty()) {
    if (!root) remove_with_sidecars(mine_path);
    remove_all();
    out.why = failed;
    return out;
  }
  if (!root) {
    out.ok = true;  // rank 0 appends this rank's slice, then removes it
    return out;
  }
  const auto t1 = std::chrono::steady_clock::now();
  try {
    std::vector<AppendRun> runs;
    std::vector<std::pair<std::string, std::uint64_t>> totals;
    for (char kind : {'p', 'm'}) {
      if (kind == 'm' && !with_members) continue;
      std::uint64_t total = 0;
      const std::string table = kind == 'p' ? plans_table : std::string("plan_members");
      for (const RankRun& r : ordered_runs(texts, kind, &total))
        if (r.rank != 0)  // rank 0's rows are in the destination already
          runs.push_back({slice_of(r.rank), table, static_cast<std::int64_t>(r.fids.first),
                          static_cast<std::int64_t>(r.fids.last)});
      totals.emplace_back(table, total);
    }
    append_runs(w.dst, runs);
    for (const auto& [table, total] : totals) check_rows(w.dst, table, total);
  } catch (const std::exception& e) {
    remove_all();
    out.why = std::string("appending the ranks' slices failed: ") + e.what();
    return out;
  }
  for (int r = 1; r < ex.size(); ++r) remove_with_sidecars(slice_of(r));
  out.append_s = seconds_since(t1);
  out.slices = static_cast<std::size_t>(ex.size());
  out.ok = true;
  return out;
}

}  // namespace groundplan::output

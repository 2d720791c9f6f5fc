// SPDX-License-Identifier: MIT
// A GeoPackage's R-tree spatial index packed in one pass (gpkg_rtree.h says why).
//
// Storage of SQLite's rtree module (ext/rtree/rtree.c, "Database Format of R-Tree Tables"), 2D:
// - %_node(nodeno, data): one blob per node, all of the size SQLite chose when the table was made (the
//   root's length says it): a 16-bit big-endian depth (the root's: the tree's height; 0 elsewhere),
//   a 16-bit cell count, then cells of 24 bytes: a 64-bit big-endian rowid (a feature id in a leaf, a
//   child's nodeno above) and minx, maxx, miny, maxy as big-endian 32-bit floats. The root is node 1.
// - %_rowid(rowid, nodeno): the leaf that holds each feature; %_parent(nodeno, parentnode): every
//   node's parent but the root's.
// Boxes are rounded to float outwards exactly as the module rounds what an INSERT gives it, so each
// entry is the one GDAL's own index would hold.
#include "gpkg_rtree.h"
#include "sqlite_db.h"

#include <cpl_error.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_geometry.h>
#include <sqlite3.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <utility>

namespace groundplan::output {
namespace {

using sqlite::Db;
using sqlite::Failure;
using sqlite::id;
using sqlite::lit;
using sqlite::Stmt;

// SQLite's rtree rounding of a double to a float bound: down for a minimum, up for a maximum, by a
// relative step of 2^-23 where the nearest float lies on the wrong side.
constexpr double kTowardZero = 1.0 - 1.0 / 8388608.0;
constexpr double kAwayFromZero = 1.0 + 1.0 / 8388608.0;
float bound_down(double d) {
  auto f = static_cast<float>(d);
  if (f > d) f = static_cast<float>(d * (d < 0 ? kAwayFromZero : kTowardZero));
  return f;
}
float bound_up(double d) {
  auto f = static_cast<float>(d);
  if (f < d) f = static_cast<float>(d * (d < 0 ? kTowardZero : kAwayFromZero));
  return f;
}

struct Cell {
  std::int64_t id;            // a feature's fid in a leaf; the child's index in the level below otherwise
  std::array<float, 4> box;   // minx, maxx, miny, maxy
};

double get_double(const unsigned char* p, bool little) {
  unsigned char b[8];
  std::memcpy(b, p, 8);
  const std::uint16_t probe = 1;
  const bool host_little = *reinterpret_cast<const unsigned char*>(&probe) == 1;
  if (little != host_little) std::reverse(b, b + 8);
  double d;
  std::memcpy(&d, b, 8);
  return d;
}

/// The box of a GeoPackage geometry blob: from its header's envelope when it has one, else from its
/// WKB. False for an empty geometry (the spec's triggers leave those out of the index).
bool blob_box(const unsigned char* b, int n, std::int64_t fid, std::array<double, 4>& box) {
  if (n < 8 || b[0] != 'G' || b[1] != 'P') throw Failure("feature " + std::to_string(fid) + ": not a GeoPackage geometry");
  const unsigned flags = b[3];
  if (flags & 0x20) throw Failure("feature " + std::to_string(fid) + ": extended GeoPackage geometry");
  if (flags & 0x10) return false;  // empty
  const unsigned envelope = (flags >> 1) & 7;
  static constexpr int kEnvelopeBytes[] = {0, 32, 48, 48, 64};
  if (envelope > 4) throw Failure("feature " + std::to_string(fid) + ": bad envelope code");
  if (n < 8 + kEnvelopeBytes[envelope]) throw Failure("feature " + std::to_string(fid) + ": geometry blob cut short");
  if (envelope != 0) {
    const bool little = flags & 1;
    for (int i = 0; i < 4; ++i) box[i] = get_double(b + 8 + 8 * i, little);
  } else {
    OGRGeometry* g = nullptr;
    const std::size_t wkb = static_cast<std::size_t>(n - 8);
    if (OGRGeometryFactory::createFromWkb(b + 8, nullptr, &g, wkb) != OGRERR_NONE || !g)
      throw Failure("feature " + std::to_string(fid) + ": unreadable WKB");
    const bool empty = g->IsEmpty();
    OGREnvelope e;
    g->getEnvelope(&e);
    OGRGeometryFactory::destroyGeometry(g);
    if (empty) return false;
    box = {e.MinX, e.MaxX, e.MinY, e.MaxY};
  }
  for (double v : box)
    if (!std::isfinite(v)) throw Failure("feature " + std::to_string(fid) + ": envelope not finite");
  return true;
}

/// Packs `cells` into nodes of at most `m` cells (sort-tile-recursive: vertical slices by centre x,
/// each cut into nodes by centre y), every node but a lone root holding at least about m/2.
std::vector<std::vector<Cell>> pack(std::vector<Cell> cells, std::size_t m) {
  std::vector<std::vector<Cell>> nodes;
  const std::size_t n = cells.size();
  if (n <= m) {
    nodes.push_back(std::move(cells));
    return nodes;
  }
  auto by = [](int axis) {
    return [axis](const Cell& a, const Cell& b) {
      const float ca = a.box[2 * axis] + a.box[2 * axis + 1], cb = b.box[2 * axis] + b.box[2 * axis + 1];
      return ca != cb ? ca < cb : a.id < b.id;
    };
  };
  tbb::parallel_sort(cells.begin(), cells.end(), by(0));
  const std::size_t leaves = (n + m - 1) / m;
  const auto slices = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(leaves))));
  for (std::size_t s = 0; s < slices; ++s) {
    const std::size_t lo = n * s / slices, hi = n * (s + 1) / slices;
    std::sort(cells.begin() + static_cast<std::ptrdiff_t>(lo), cells.begin() + static_cast<std::ptrdiff_t>(hi), by(1));
    const std::size_t k = hi - lo, count = (k + m - 1) / m;
    for (std::size_t j = 0; j < count; ++j)
      nodes.emplace_back(cells.begin() + static_cast<std::ptrdiff_t>(lo + k * j / count),
                         cells.begin() + static_cast<std::ptrdiff_t>(lo + k * (j + 1) / count));
  }
  return nodes;
}

void put16(unsigned char* p, unsigned v) {
  p[0] = static_cast<unsigned char>(v >> 8);
  p[1] = static_cast<unsigned char>(v);
}
void put64(unsigned char* p, std::uint64_t v) {
  for (int i = 7; i >= 0; --i, v >>= 8) p[i] = static_cast<unsigned char>(v);
}
void put_float(unsigned char* p, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  for (int i = 3; i >= 0; --i, u >>= 8) p[i] = static_cast<unsigned char>(u);
}

/// The triggers the GeoPackage spec (F.3, 1.2-1.3) and GDAL 3.6 give an indexed column, word for word.
std::vector<std::string> triggers(const std::string& t, const std::string& g, const std::string& f) {
  const std::string rtree = id("rtree_" + t + "_" + g), T = id(t), G = id(g), F = id(f);
  auto name = [&](const char* suffix) { return id("rtree_" + t + "_" + g + "_" + suffix); };
  const std::string insert_new = "INSERT OR REPLACE INTO " + rtree + " VALUES (NEW." + F + ",ST_MinX(NEW." + G +
                                 "), ST_MaxX(NEW." + G + "),ST_MinY(NEW." + G + "), ST_MaxY(NEW." + G + "));";
  return {
      "CREATE TRIGGER " + name("insert") + " AFTER INSERT ON " + T + " WHEN (new." + G + " NOT NULL AND NOT ST_IsEmpty(NEW." +
          G + ")) BEGIN " + insert_new + " END",
      "CREATE TRIGGER " + name("update1") + " AFTER UPDATE OF " + G + " ON " + T + " WHEN OLD." + F + " = NEW." + F +
          " AND (NEW." + G + " NOTNULL AND NOT ST_IsEmpty(NEW." + G + ")) BEGIN " + insert_new + " END",
      "CREATE TRIGGER " + name("update2") + " AFTER UPDATE OF " + G + " ON " + T + " WHEN OLD." + F + " = NEW." + F +
          " AND (NEW." + G + " ISNULL OR ST_IsEmpty(NEW." + G + ")) BEGIN DELETE FROM " + rtree + " WHERE id = OLD." + F +
          "; END",
      "CREATE TRIGGER " + name("update3") + " AFTER UPDATE ON " + T + " WHEN OLD." + F + " != NEW." + F + " AND (NEW." +
          G + " NOTNULL AND NOT ST_IsEmpty(NEW." + G + ")) BEGIN DELETE FROM " + rtree + " WHERE id = OLD." + F + "; " +
          insert_new + " END",
      "CREATE TRIGGER " + name("update4") + " AFTER UPDATE ON " + T + " WHEN OLD." + F + " != NEW." + F + " AND (NEW." +
          G + " ISNULL OR ST_IsEmpty(NEW." + G + ")) BEGIN DELETE FROM " + rtree + " WHERE id IN (OLD." + F + ", NEW." +
          F + "); END",
      "CREATE TRIGGER " + name("delete") + " AFTER DELETE ON " + T + " WHEN old." + G + " NOT NULL BEGIN DELETE FROM " +
          rtree + " WHERE id = OLD." + F + "; END",
  };
}

bool table_exists(const Db& db, const std::string& name) {
  Stmt s(db, "SELECT 1 FROM sqlite_master WHERE name = " + lit(name));
  return s.row();
}

struct GeomColumn {
  std::string table, column;
};

std::vector<GeomColumn> geometry_columns(const Db& db) {
  std::vector<GeomColumn> out;
  if (!table_exists(db, "gpkg_geometry_columns")) return out;
  Stmt s(db, "SELECT table_name, column_name FROM gpkg_geometry_columns");
  while (s.row()) out.push_back({s.text(0), s.text(1)});
  return out;
}

/// The table's INTEGER PRIMARY KEY column (the feature id).
std::string fid_column(const Db& db, const std::string& table) {
  Stmt s(db, "PRAGMA table_info(" + id(table) + ")");
  std::string fid;
  int keys = 0;
  while (s.row())
    if (sqlite3_column_int(s.get(), 5) > 0) {
      ++keys;
      fid = s.text(1);
    }
  if (keys != 1) throw Failure(table + ": no single integer primary key");
  return fid;
}

/// The index entries of a table, in fid order: its features' boxes rounded outwards to float. The
/// geometries are most of the file, so fid ranges are read side by side, one read-only connection each.
std::vector<Cell> read_entries(const std::string& path, const Db& db, const GeomColumn& gc, const std::string& f,
                               int threads) {
  const std::string& t = gc.table;
  const std::string& g = gc.column;
  std::int64_t lo = 0, hi = -1;
  {
    Stmt s(db, "SELECT min(" + id(f) + "), max(" + id(f) + ") FROM " + id(t));
    if (s.row() && sqlite3_column_type(s.get(), 0) != SQLITE_NULL) {
      lo = sqlite3_column_int64(s.get(), 0);
      hi = sqlite3_column_int64(s.get(), 1);
    }
  }
  if (hi < lo) return {};
  const std::uint64_t span = static_cast<std::uint64_t>(hi) - static_cast<std::uint64_t>(lo) + 1;
  const std::size_t parts = static_cast<std::size_t>(std::min<std::uint64_t>(span / 4096 + 1, 4u * static_cast<unsigned>(threads)));
  std::vector<std::vector<Cell>> got(parts);
  std::vector<std::string> errors(parts);
  const std::string sql = "SELECT " + id(f) + ", " + id(g) + " FROM " + id(t) + " WHERE " + id(f) + " BETWEEN ? AND ? AND " +
                          id(g) + " IS NOT NULL ORDER BY " + id(f);
  tbb::task_arena arena(std::max(1, threads));
  arena.execute([&] {
    tbb::parallel_for(std::size_t{0}, parts, [&](std::size_t k) {
      try {
        const Db reader(path, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX);
        const Stmt s(reader, sql);
        const auto from = static_cast<std::int64_t>(static_cast<std::uint64_t>(lo) + span * k / parts);
        const auto to = static_cast<std::int64_t>(static_cast<std::uint64_t>(lo) + span * (k + 1) / parts - 1);
        sqlite3_bind_int64(s.get(), 1, from);
        sqlite3_bind_int64(s.get(), 2, to);
        std::array<double, 4> box{};
        while (s.row()) {
          const std::int64_t fid = sqlite3_column_int64(s.get(), 0);
          const auto* blob = static_cast<const unsigned char*>(sqlite3_column_blob(s.get(), 1));
          if (!blob_box(blob, sqlite3_column_bytes(s.get(), 1), fid, box)) continue;
          got[k].push_back({fid, {bound_down(box[0]), bound_up(box[1]), bound_down(box[2]), bound_up(box[3])}});
        }
      } catch (const Failure& e) {
        errors[k] = e.what();
      }
    });
  });
  std::vector<Cell> entries;
  for (std::size_t k = 0; k < parts; ++k) {
    if (!errors[k].empty()) throw Failure(t + ": " + errors[k]);
    entries.insert(entries.end(), got[k].begin(), got[k].end());
  }
  return entries;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Rows of two integers into one table, kRows to an INSERT (one multi-row VALUES statement, prepared once), not a
/// statement step and reset a row: the index's write on 609,088 entries went 0.63 -> 0.47 s (medians, 16-core host;
/// 0.75 -> 0.38 s on the 2-core VM for 600,000; tests/bench/RESULTS.md).
class PairInserter {
 public:
  PairInserter(const Db& db, std::string head) : db_(db), head_(std::move(head)) {}
  void add(std::int64_t a, std::int64_t b) {
    rows_.emplace_back(a, b);
    if (rows_.size() == kRows) flush();
  }
  void flush() {
    if (rows_.empty()) return;
    if (rows_.size() == kRows) {
      if (!full_) full_ = std::make_unique<Stmt>(db_, sql(kRows));
      run(*full_);
    } else {
      Stmt tail(db_, sql(rows_.size()));
      run(tail);
    }
    rows_.clear();
  }

 private:
  static constexpr std::size_t kRows = 256;  // 512 bound values, under every SQLite's variable limit (999 before 3.32)
  std::string sql(std::size_t n) const {
    std::string q = head_ + " VALUES (?,?)";
    for (std::size_t i = 1; i < n; ++i) q += ",(?,?)";
    return q;
  }
  void run(const Stmt& st) {
    int k = 1;
    for (const auto& [a, b] : rows_) {
      sqlite3_bind_int64(st.get(), k++, a);
      sqlite3_bind_int64(st.get(), k++, b);
    }
    st.run();
  }
  const Db& db_;
  std::string head_;
  std::vector<std::pair<std::int64_t, std::int64_t>> rows_;
  std::unique_ptr<Stmt> full_;
};

/// One table's index, inside the caller's transaction. Returns the number of entries.
std::size_t build_one(const std::string& path, const Db& db, const GeomColumn& gc, int threads, RtreeBuild& times) {
  const std::string& t = gc.table;
  const std::string& g = gc.column;
  const std::string f = fid_column(db, t);
  const std::string name = "rtree_" + t + "_" + g;
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<Cell> entries = read_entries(path, db, gc, f, threads);
  times.read_s += seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  if (!table_exists(db, "gpkg_extensions"))
    db.exec("CREATE TABLE gpkg_extensions (table_name TEXT,column_name TEXT,extension_name TEXT NOT NULL,definition "
            "TEXT NOT NULL,scope TEXT NOT NULL,CONSTRAINT ge_tce UNIQUE (table_name, column_name, extension_name))");
  db.exec("CREATE VIRTUAL TABLE " + id(name) + " USING rtree(id, minx, maxx, miny, maxy)");

  // The node size SQLite chose for this database's page size (its empty root says it).
  std::size_t node_bytes = 0;
  {
    Stmt s(db, "SELECT length(data) FROM " + id(name + "_node") + " WHERE nodeno = 1");
    if (!s.row()) throw Failure(name + ": no root node after CREATE VIRTUAL TABLE");
    node_bytes = static_cast<std::size_t>(sqlite3_column_int64(s.get(), 0));
  }
  const std::size_t m = node_bytes >= 4 ? (node_bytes - 4) / 24 : 0;
  if (m < 4) throw Failure(name + ": unexpected rtree node size " + std::to_string(node_bytes));

  if (!entries.empty()) {
    PairInserter rowid(db, "INSERT INTO " + id(name + "_rowid") + "(rowid, nodeno)");
    Stmt node(db, "INSERT OR REPLACE INTO " + id(name + "_node") + "(nodeno, data) VALUES (?, ?)");
    PairInserter parent(db, "INSERT INTO " + id(name + "_parent") + "(nodeno, parentnode)");

    // Levels bottom up; a level's cells name their children by index in the level below.
    std::vector<std::vector<std::vector<Cell>>> levels;
    levels.push_back(pack(entries, m));
    while (levels.back().size() > 1) {
      const auto& below = levels.back();
      std::vector<Cell> up(below.size());
      for (std::size_t k = 0; k < below.size(); ++k) {
        std::array<float, 4> b = below[k][0].box;
        for (const Cell& c : below[k]) {
          b[0] = std::min(b[0], c.box[0]), b[1] = std::max(b[1], c.box[1]);
          b[2] = std::min(b[2], c.box[2]), b[3] = std::max(b[3], c.box[3]);
        }
        up[k] = {static_cast<std::int64_t>(k), b};
      }
      levels.push_back(pack(std::move(up), m));
    }
    // Node numbers top down: the root is 1, then each level in order.
    const std::size_t height = levels.size();
    std::vector<std::vector<std::int64_t>> number(height);
    std::int64_t next = 1;
    for (std::size_t l = height; l-- > 0;) {
      number[l].resize(levels[l].size());
      for (auto& nr : number[l]) nr = next++;
    }
    std::vector<unsigned char> data(node_bytes);
    for (std::size_t l = height; l-- > 0;) {
      for (std::size_t k = 0; k < levels[l].size(); ++k) {
        const std::vector<Cell>& cells = levels[l][k];
        std::fill(data.begin(), data.end(), 0);
        put16(data.data(), l + 1 == height ? static_cast<unsigned>(height - 1) : 0);
        put16(data.data() + 2, static_cast<unsigned>(cells.size()));
        unsigned char* p = data.data() + 4;
        for (const Cell& c : cells) {
          const std::int64_t child = l == 0 ? c.id : number[l - 1][static_cast<std::size_t>(c.id)];
          put64(p, static_cast<std::uint64_t>(child));
          for (int i = 0; i < 4; ++i) put_float(p + 8 + 4 * i, c.box[i]);
          p += 24;
          if (l > 0) parent.add(child, number[l][k]);
        }
        sqlite3_bind_int64(node.get(), 1, number[l][k]);
        sqlite3_bind_blob(node.get(), 2, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
        node.run();
      }
    }
    // Each feature's leaf, in fid order (appending to the rowid table's B-tree).
    std::vector<std::pair<std::int64_t, std::int64_t>> leaf_of;
    leaf_of.reserve(entries.size());
    for (std::size_t k = 0; k < levels[0].size(); ++k)
      for (const Cell& c : levels[0][k]) leaf_of.emplace_back(c.id, number[0][k]);
    std::sort(leaf_of.begin(), leaf_of.end());
    parent.flush();
    for (const auto& [fid, leaf] : leaf_of) rowid.add(fid, leaf);
    rowid.flush();
  }
  for (const std::string& sql : triggers(t, g, f)) db.exec(sql);
  db.exec("INSERT INTO gpkg_extensions (table_name, column_name, extension_name, definition, scope) VALUES (" + lit(t) +
          ", " + lit(g) + ", 'gpkg_rtree_index', 'http://www.geopackage.org/spec120/#extension_rtree', 'write-only')");
  times.write_s += seconds_since(t0);
  return entries.size();
}

std::vector<GeomColumn> unindexed(const Db& db) {
  std::vector<GeomColumn> out;
  for (GeomColumn& gc : geometry_columns(db))
    if (!table_exists(db, "rtree_" + gc.table + "_" + gc.column)) out.push_back(std::move(gc));
  return out;
}

bool is_gpkg_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  char head[16] = {};
  const std::size_t n = std::fread(head, 1, sizeof head, f);
  std::fclose(f);
  return n == sizeof head && std::memcmp(head, "SQLite format 3", 16) == 0;
}

}  // namespace

std::vector<std::string> gpkg_unindexed_tables(const std::string& path) {
  std::vector<std::string> out;
  if (!is_gpkg_file(path)) return out;
  try {
    const Db db(path);
    for (const GeomColumn& gc : unindexed(db)) out.push_back(gc.table);
  } catch (const Failure&) {
  }
  return out;
}

RtreeBuild build_gpkg_rtrees(const std::string& path, int threads) {
  RtreeBuild out;
  try {
    const Db db(path);
    db.exec("PRAGMA cache_size = -65536");  // 64 MiB: the tree's pages are written once, not evicted and re-read
    for (const GeomColumn& gc : unindexed(db)) {
      db.exec("BEGIN");
      try {
        out.entries += build_one(path, db, gc, threads, out);
        const auto t0 = std::chrono::steady_clock::now();
        db.exec("COMMIT");
        out.commit_s += seconds_since(t0);
      } catch (...) {
        sqlite3_exec(db.get(), "ROLLBACK", nullptr, nullptr, nullptr);
        throw;
      }
      ++out.tables;
    }
  } catch (const Failure& e) {
    out.error = e.what();
  }
  return out;
}

bool index_new_gpkg(const std::string& path, int threads, RtreeBuild& built, bool packed) {
  if (packed) {
    built = build_gpkg_rtrees(path, threads);
    if (built.error.empty()) return true;
  }
  built.by_gdal = true;
  GDALDatasetH ds = GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, nullptr, nullptr, nullptr);
  if (!ds) return false;
  for (const std::string& table : gpkg_unindexed_tables(path)) {
    OGRLayerH layer = GDALDatasetGetLayerByName(ds, table.c_str());
    const char* geom = layer ? OGR_L_GetGeometryColumn(layer) : nullptr;
    if (!geom || !*geom) continue;
    const std::string sql = "SELECT CreateSpatialIndex(" + lit(table) + ", " + lit(geom) + ")";
    if (OGRLayerH r = GDALDatasetExecuteSQL(ds, sql.c_str(), nullptr, nullptr)) GDALDatasetReleaseResultSet(ds, r);
  }
  CPLErrorReset();
  GDALClose(ds);
  return CPLGetLastErrorType() < CE_Failure && gpkg_unindexed_tables(path).empty();
}

}  // namespace groundplan::output

// SPDX-License-Identifier: MIT
#pragma once
// A few lines over SQLite's C API for the CLI's own work on GeoPackages it has just written (gpkg_rtree.h,
// gpkg_slices.h): a connection and a statement that close themselves and throw on error.
#include <sqlite3.h>

#include <stdexcept>
#include <string>

namespace groundplan::output::sqlite {

struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// One connection; throws Failure (naming the file) when it cannot be opened.
class Db {
 public:
  explicit Db(const std::string& path, int flags = SQLITE_OPEN_READWRITE) {
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
      const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      throw Failure(path + ": " + why);
    }
  }
  ~Db() { sqlite3_close(db_); }
  Db(const Db&) = delete;
  Db& operator=(const Db&) = delete;
  sqlite3* get() const { return db_; }
  void exec(const std::string& sql) const {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string why = err ? err : sqlite3_errmsg(db_);
      sqlite3_free(err);
      throw Failure(why + " (in: " + sql.substr(0, 120) + ")");
    }
  }

 private:
  sqlite3* db_ = nullptr;
};

class Stmt {
 public:
  Stmt(const Db& db, const std::string& sql) : db_(db.get()) {
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &s_, nullptr) != SQLITE_OK)
      throw Failure(std::string(sqlite3_errmsg(db_)) + " (in: " + sql.substr(0, 120) + ")");
  }
  ~Stmt() { sqlite3_finalize(s_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  sqlite3_stmt* get() const { return s_; }
  bool row() const {  // steps once: true on a row, false when done
    const int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) throw Failure(sqlite3_errmsg(db_));
    return false;
  }
  void run() const {  // steps a statement that gives no rows, and makes it ready for the next bindings
    row();
    sqlite3_reset(s_);
  }
  std::string text(int col) const {
    const auto* t = sqlite3_column_text(s_, col);
    return t ? reinterpret_cast<const char*>(t) : "";
  }

 private:
  sqlite3* db_;
  sqlite3_stmt* s_ = nullptr;
};

/// "name" with embedded quotes doubled: an SQL identifier.
inline std::string id(const std::string& name) {
  std::string out = "\"";
  for (char c : name) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// 'text' with embedded quotes doubled: an SQL string literal.
inline std::string lit(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

}  // namespace groundplan::output::sqlite

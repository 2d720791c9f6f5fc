// SPDX-License-Identifier: MIT
#include "pg_staging.h"

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <ctime>

namespace groundplan::output {

std::string gdal_error(const std::string& fallback) {
  const char* m = CPLGetLastErrorMsg();
  return m && *m ? std::string(m) : fallback;
}

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// `text` as an SQL string literal.
std::string quoted_literal(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

/// An open PostgreSQL datasource, closed when it goes.
class Connection {
 public:
  Connection(const std::string& dst, const CPLStringList& open_options) {
    const char* const drivers[] = {"PostgreSQL", nullptr};
    CPLErrorReset();
    ds_ = GDALOpenEx(dst.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, drivers, open_options.List(), nullptr);
    if (!ds_) error_ = "cannot open " + dst + ": " + gdal_error("no PostgreSQL datasource");
  }
  ~Connection() {
    if (ds_) GDALClose(ds_);
  }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  const std::string& error() const { return error_; }
  GDALDatasetH handle() const { return ds_; }

  /// Runs a statement; empty, or why it failed.
  std::string exec(const std::string& sql) {
    CPLErrorReset();
    OGRLayerH rs = GDALDatasetExecuteSQL(ds_, sql.c_str(), nullptr, nullptr);
    if (rs) GDALDatasetReleaseResultSet(ds_, rs);
    return CPLGetLastErrorType() >= CE_Failure ? sql + ": " + gdal_error("failed") : std::string();
  }

  /// The first column of every row a query gives, as text; nullopt when it fails.
  std::optional<std::vector<std::string>> column(const std::string& sql) {
    CPLErrorReset();
    OGRLayerH rs = GDALDatasetExecuteSQL(ds_, sql.c_str(), nullptr, nullptr);
    if (!rs || CPLGetLastErrorType() >= CE_Failure) {
      if (rs) GDALDatasetReleaseResultSet(ds_, rs);
      return std::nullopt;
    }
    std::vector<std::string> out;
    OGRLayer* layer = OGRLayer::FromHandle(rs);
    for (auto& f : *layer) out.emplace_back(f->GetFieldAsString(0));
    GDALDatasetReleaseResultSet(ds_, rs);
    return out;
  }

 private:
  GDALDatasetH ds_ = nullptr;
  std::string error_;
};

/// The user's -lco values with key `key` (case as the user wrote it: GDAL's keys are case-insensitive).
bool has_layer_option(const std::vector<std::string>& options, const std::string& key) {
  for (std::size_t i = 0; i + 1 < options.size(); ++i)
    if (options[i] == "-lco" && lower(options[i + 1]).rfind(lower(key) + "=", 0) == 0) return true;
  return false;
}

}  // namespace

std::string quoted_identifier(const std::string& name) {
  std::string out = "\"";
  for (char c : name) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string PgStaging::staged_dst() const { return dst + " active_schema=" + schema; }

std::string why_tables_in_place(const std::string& dst, const std::vector<std::string>& options,
                                const std::vector<std::string>& tables,
                                const std::optional<std::vector<std::string>>& before) {
  const std::string d = lower(dst);
  if (d.rfind("pg:", 0) != 0) return "the datasource is not a PG: connection string";
  if (d.find("://") != std::string::npos) return "the connection is a URI (active_schema cannot be added to it)";
  if (d.find("active_schema") != std::string::npos || d.find("schemas") != std::string::npos)
    return "the connection string chooses the schemas";
  if (has_layer_option(options, "SCHEMA")) return "-lco SCHEMA chooses the schema";
  for (const std::string& t : tables)
    if (t.find('.') != std::string::npos) return "the table name " + t + " names a schema";
  if (!before) return "the datasource could not be opened before the run";
  const bool overwrite = std::find(options.begin(), options.end(), "-overwrite") != options.end();
  if (!before->empty() && !overwrite) return "appends to the existing table " + before->front();
  return {};
}

std::optional<PgStaging> make_staging_schema(const std::string& dst, const CPLStringList& open_options,
                                             std::string* error) {
  Connection c(dst, open_options);
  if (!c.error().empty()) {
    *error = c.error();
    return std::nullopt;
  }
  const auto target = c.column("SELECT current_schema()");
  if (!target || target->size() != 1 || target->front().empty()) {
    *error = "cannot tell the connection's current schema: " + gdal_error("no current schema");
    return std::nullopt;
  }
  PgStaging s;
  s.dst = dst;
  s.target = target->front();
  if (const auto found = c.column("SELECT nspname || ': ' || coalesce(obj_description(oid, 'pg_namespace'), '') "
                                  "FROM pg_namespace WHERE nspname LIKE 'groundplan\\_partial\\_%' ORDER BY 1"))
    s.found = *found;
  const auto ticks = std::chrono::steady_clock::now().time_since_epoch().count();
  s.schema = "groundplan_partial_" + std::to_string(::getpid()) + "_" + std::to_string(ticks % 1000000007);
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  char when[32] = {};
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", std::gmtime(&now));
  const std::string what =
      "groundplan: the tables of a run over MPI ranks that has not finished (rank 0: pid " + std::to_string(::getpid()) +
      " on " + host + ", started " + when + " UTC). They are moved into schema " + s.target +
      " once every rank has written; if that run is no longer running, DROP SCHEMA " + quoted_identifier(s.schema) +
      " CASCADE removes them.";
  std::string why = c.exec("CREATE SCHEMA " + quoted_identifier(s.schema));
  if (why.empty()) why = c.exec("COMMENT ON SCHEMA " + quoted_identifier(s.schema) + " IS " + quoted_literal(what));
  if (!why.empty()) {
    c.exec("DROP SCHEMA IF EXISTS " + quoted_identifier(s.schema) + " CASCADE");
    *error = "cannot make the staging schema: " + why;
    return std::nullopt;
  }
  return s;
}

std::string move_staged_tables(const PgStaging& s, const CPLStringList& open_options, bool replace) {
  Connection c(s.dst, open_options);
  if (!c.error().empty()) return c.error();
  const auto tables =
      c.column("SELECT tablename FROM pg_tables WHERE schemaname = " + quoted_literal(s.schema) + " ORDER BY 1");
  if (!tables) return "cannot list the staged tables: " + gdal_error("query failed");
  CPLErrorReset();
  if (GDALDatasetStartTransaction(c.handle(), FALSE) != OGRERR_NONE)
    return "cannot start a transaction: " + gdal_error("the driver refused");
  std::string why;
  const std::string to = quoted_identifier(s.target);
  for (const std::string& t : *tables) {
    if (why.empty() && replace) why = c.exec("DROP TABLE IF EXISTS " + to + "." + quoted_identifier(t) + " CASCADE");
    if (why.empty())
      why = c.exec("ALTER TABLE " + quoted_identifier(s.schema) + "." + quoted_identifier(t) + " SET SCHEMA " + to);
  }
  if (why.empty()) why = c.exec("DROP SCHEMA " + quoted_identifier(s.schema));  // empty now, or it fails
  CPLErrorReset();
  if (!why.empty()) {
    GDALDatasetRollbackTransaction(c.handle());
    return why;
  }
  if (GDALDatasetCommitTransaction(c.handle()) != OGRERR_NONE) return "commit failed: " + gdal_error("");
  return {};
}

std::string advance_id_sequences(const std::string& dst, const CPLStringList& open_options,
                                 const std::vector<std::string>& tables, const std::string& schema) {
  Connection c(dst, open_options);
  if (!c.error().empty()) return c.error();
  GDALDataset* ds = GDALDataset::FromHandle(c.handle());
  for (const std::string& t : tables) {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    OGRLayer* layer = ds->GetLayerByName(t.c_str());
    CPLPopErrorHandler();
    if (!layer) continue;
    const std::string fid = layer->GetFIDColumn();
    if (fid.empty()) continue;
    // GDAL names a table outside the current schema "schema.table".
    std::string name = layer->GetName(), in = schema;
    if (in.empty()) {
      const std::size_t dot = name.find('.');
      if (dot != std::string::npos) {
        in = name.substr(0, dot);
        name = name.substr(dot + 1);
      }
    }
    const std::string table = (in.empty() ? std::string() : quoted_identifier(in) + ".") + quoted_identifier(name);
    // setval is strict: no sequence (an id column that is not serial) or no row (max NULL) sets nothing.
    const std::string why = c.exec("SELECT setval(pg_get_serial_sequence(" + quoted_literal(table) + ", " +
                                   quoted_literal(fid) + "), max(" + quoted_identifier(fid) + ")) FROM " + table);
    if (!why.empty()) return why;
  }
  return {};
}

std::string drop_staging_schema(const PgStaging& s, const CPLStringList& open_options) {
  Connection c(s.dst, open_options);
  if (!c.error().empty()) return c.error();
  return c.exec("DROP SCHEMA IF EXISTS " + quoted_identifier(s.schema) + " CASCADE");
}

}  // namespace groundplan::output

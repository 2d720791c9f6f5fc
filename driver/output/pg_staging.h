// SPDX-License-Identifier: MIT
#pragma once
// Issue 15: the tables of `mpirun -np N groundplan ... -f PostgreSQL PG:...` are made in a schema of their own (a
// staging schema, `groundplan_partial_<pid>_<n>`), every rank writes its rows there, and rank 0 moves the tables
// into the schema asked for in one transaction once every rank has committed. Until that transaction the user's
// schema holds nothing of the run: a rank that is killed (mpirun ends the others, no rank is left to clean up) leaves
// at most the staging schema, whose comment says what it is, never empty or half-written tables under the names asked
// for; and `-overwrite` replaces the old tables only in that transaction. The PostgreSQL analogue of the hidden
// staging folder a file destination gets (staged_output.h).
#include <cpl_string.h>

#include <optional>
#include <string>
#include <vector>

namespace groundplan::output {

/// GDAL's last error message, or `fallback` when there is none (also used by rank_writes.cpp).
std::string gdal_error(const std::string& fallback);

/// Why the run's tables are written in place, in the user's schema (empty: they can be staged). Staging needs the
/// schema asked for to be the connection's current one, named by nothing but the connection itself (not by
/// active_schema= or schemas= in it, -lco SCHEMA= or a dotted -nln), a "key=value" connection string (active_schema is
/// added to it), and every target table either new or replaced (-overwrite): appending to a table that exists stays
/// in place, as GDAL's ogr2ogr does it. `before` is which of `tables` exist (nullopt: the datasource did not open).
std::string why_tables_in_place(const std::string& dst, const std::vector<std::string>& options,
                                const std::vector<std::string>& tables,
                                const std::optional<std::vector<std::string>>& before);

/// A staging schema made for one run.
struct PgStaging {
  std::string dst;     // the user's datasource
  std::string schema;  // the staging schema
  std::string target;  // the schema the tables go to (the connection's current one)
  /// Staging schemas already there when this one was made (runs that were killed, or that run now), each with
  /// its comment: "name: comment".
  std::vector<std::string> found;
  /// The datasource with the staging schema as its active schema: what rank 0 makes the tables in and every rank
  /// appends to (GDAL's layer names then resolve there, so `-overwrite` does not reach the user's tables early).
  std::string staged_dst() const;
};

/// Makes the staging schema in `dst` (a new name, with a comment saying what it is); `error` says why not.
std::optional<PgStaging> make_staging_schema(const std::string& dst, const CPLStringList& open_options,
                                             std::string* error);

/// Moves every table of the staging schema into the target schema and drops the staging schema, in one
/// transaction; with `replace`, a table of the same name there is dropped first (-overwrite, as GDAL drops it:
/// CASCADE). Empty, or why not (the transaction is then rolled back: the target schema is as it was).
std::string move_staged_tables(const PgStaging& s, const CPLStringList& open_options, bool replace);

/// Sets the id sequence of each of `tables` (by GDAL layer name in `dst`; in `schema` where it is not empty) past
/// its largest FID, once every rank has committed. Each rank's GDAL sets it when it closes the datasource, but
/// from the largest id that rank saw: a rank whose statement ran before another's commit could leave the sequence
/// behind the other's rows, so a later plain append would collide. Empty, or why not.
std::string advance_id_sequences(const std::string& dst, const CPLStringList& open_options,
                                 const std::vector<std::string>& tables, const std::string& schema);

/// Drops the staging schema and what is in it; empty, or why not.
std::string drop_staging_schema(const PgStaging& s, const CPLStringList& open_options);

/// `name` as a PostgreSQL identifier in double quotes.
std::string quoted_identifier(const std::string& name);

}  // namespace groundplan::output

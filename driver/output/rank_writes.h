// SPDX-License-Identifier: MIT
#pragma once
// `mpirun -np N groundplan ... -f PostgreSQL PG:...` (issue 15 stage 5): every rank writes its own final plans into
// the one database, side by side, instead of streaming them to rank 0. Rank 0 creates the tables (the user's
// ogr2ogr options: -lco, -overwrite, -nln ...), every rank then appends its share in one transaction of its own, and
// the transactions are committed only once every rank has written all of its rows (an allgather of their outcome):
// a rank that dies before leaves every transaction open, and PostgreSQL rolls them back when mpirun ends the job.
// Where it can, rank 0 makes the tables in a staging schema and moves them into the user's schema in one
// transaction after every commit (pg_staging.h), so a run that dies leaves nothing under the names asked for.
// docs/ARCHITECTURE.md ("Many machines") says what is left for a rank that dies inside the commits.
#include <groundplan/gis/tiled.h>

#include <gdal_priv.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace groundplan::output {

/// True for an output that every rank writes itself: OGR's PostgreSQL driver (-f PostgreSQL, or a PG: name
/// without -f). Files keep rank 0 as their only writer.
bool written_by_every_rank(const std::string& format, const std::string& dst);

/// The user's ogr2ogr options for a rank's append into tables rank 0 has made: what only creating means (-f, -lco,
/// -dsco, -overwrite) and the user's transaction settings (-gt, -ds_transaction, -lyr_transaction) are left out;
/// -append, "-gt unlimited" (one transaction: the rank's own, see rank_writes.cpp) and -preserve_fid (feature ids as in the one
/// dataset: ogc_fid = gp_id) are added; -preserve_fid not where -unsetFid or -explodecollections asks otherwise, nor
/// without `own_ids` (a table that existed before the run may hold rows whose ids these would repeat: the database's
/// sequence numbers the new rows then, as GDAL's ogr2ogr -append does in one process).
std::vector<std::string> append_options(const std::vector<std::string>& options, bool own_ids = true);

/// Every rank's `text`, in rank order (an allgather; also used by gpkg_rank_slices.cpp).
std::vector<std::string> gather_text(gis::TileExchange& ex, const std::string& text);

/// What rank 0 needs to create the tables.
struct TableSetup {
  std::string dst;                   // the PG: datasource
  std::vector<std::string> options;  // the user's ogr2ogr options and layer names, as for one process
  bool create = true;                // false: rank 0 has nothing to write (says so itself); every rank stops
  std::vector<std::string> tables;   // the tables the run writes (the layers' names, or -nln's): those of them
                                     // that did not exist before are dropped again when the run fails
};

/// The outcome of a write by every rank.
struct RankWrite {
  bool ok = false;     // every rank wrote and committed
  std::string why;     // otherwise: what failed, on which rank (rank 0 has the whole story)
  std::vector<std::string> dropped;  // rank 0, on failure: the tables this run had made and dropped again
  double write_s = 0;  // this rank: creating (rank 0) + appending + committing (+ moving, rank 0)
  std::string staging_schema;  // rank 0: the schema the tables were made in before the move (pg_staging.h)
  std::string in_place;        // rank 0: why they were made in the user's schema instead; empty when staged
  std::vector<std::string> left_over;  // rank 0: staging schemas of earlier runs found in the database
  std::vector<std::string> warnings;   // rank 0: what went wrong after the rows were committed in place
};

/// Collective over `ex`: rank 0 creates the tables from `empty_layers` (the layers of `mine` without features,
/// in the working CRS; in a staging schema where pg_staging.h allows), every rank appends the layers of `mine` (its
/// share) in a transaction of its own and commits once every rank has written, and rank 0 then moves staged tables
/// into the user's schema. Both datasets are taken (closed here). `before_commit` (a test hook) runs after
/// this rank's rows are written, before the outcome is exchanged. A write that fails or throws does not throw:
/// every rank learns it, every transaction is rolled back (or, where a commit failed, the others' rows stay), and
/// rank 0 then drops the tables of `setup.tables` that it made in this run (none that existed before); MPI
/// failures throw (mpirun ends the job: PostgreSQL rolls back, but the tables made stay).
RankWrite write_from_every_rank(gis::TileExchange& ex, const TableSetup& setup, GDALDataset* mine,
                                GDALDataset* empty_layers, const std::function<void()>& before_commit);

}  // namespace groundplan::output

// SPDX-License-Identifier: MIT
#pragma once
// A new GeoPackage written by several GDAL writers at once (issue 14).
//
// GDAL's GeoPackage writer is one thread (one SQLite connection): at city scale it was the longest serial
// stage left (121,856 plans: 1.2-1.5 s of a 3.5 s run on 16 cores, RESULTS.md). Here the plans layer is cut
// into contiguous slices of features; each slice is written by its own ogr2ogr (GDALVectorTranslate, the
// user's options unchanged, FIDs kept) into its own file, slice 0 straight into the destination together with
// the other layers asked for; then the other slices' rows are appended to the destination's table in slice
// order by SQLite itself (one INSERT ... SELECT a slice, which SQLite copies record by record), and the
// table's extent and feature count are set for all of them. What a reader gets is what one writer gives:
// the same tables, schema, rows, FIDs (1..N in plan order), extent and count; only the file's page layout
// differs. The spatial index is packed afterwards as for any new GeoPackage (gpkg_rtree.h).
#include "sqlite_db.h"

#include <gdal.h>

#include <cstddef>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::output {

/// SQLite keeps process-wide memory statistics behind one global mutex, taken by every allocation of every
/// connection: writers side by side wait on it. Turns them off; call before SQLite is first used (first
/// thing in main). SQLite's own limits that rely on them (soft heap limit) are not used here.
void sqlite_without_memory_statistics();

/// How many writers a new GeoPackage gets; 1 (and `why_one` says why) when it is written by one writer as
/// before: few plans or threads, or an ogr2ogr option whose effect spans features (-where, -sql, -limit,
/// -explodecollections ...). `flags`: the ogr2ogr options without the layer names.
int gpkg_writers(const std::vector<std::string>& flags, const std::vector<std::string>& layers,
                 const std::string& plans_layer, std::size_t plans, int threads, std::string* why_one);

/// Why the plans layer cannot be written in slices (empty: it can): the layer is not written, an ogr2ogr option
/// whose effect spans features, -nln with several layers. Used by gpkg_writers and by the MPI ranks
/// (gpkg_rank_slices.h).
std::string slices_ruled_out(const std::vector<std::string>& flags, const std::vector<std::string>& layers,
                             const std::string& plans_layer);

/// The plans layer's table name: `plans_layer`, or what -nln says.
std::string table_name(const std::vector<std::string>& flags, const std::string& plans_layer);

/// Removes a file and the journal files SQLite may leave beside it (nothing said when they are not there).
void remove_with_sidecars(const std::string& path);

/// Rows of one table of a slice file to append to the destination: those with FIDs (rowids) first..last, or all
/// of them where last < first.
struct AppendRun {
  std::string part;   // the slice file
  std::string table;  // the same table in both files
  std::int64_t first = 0, last = -1;
};

/// append_runs one run at a time, for a writer that appends each slice as soon as it is written (streamed_gpkg.h):
/// opening takes the tables' triggers off, finish() sets the feature counts and puts the triggers back.
class Appender {
 public:
  Appender(const std::string& dst, const std::vector<std::string>& tables);
  void append(const AppendRun& run);  // one transaction; `run.table` must be one of `tables`
  void finish();

 private:
  sqlite::Db db_;
  std::vector<std::string> tables_;
  std::vector<std::array<std::string, 2>> triggers_;  // name, sql
  bool has_ogr_contents_ = false;
};

/// Appends the runs to the GeoPackage `dst` in the order given, one transaction each (SQLite copies the records;
/// FIDs are kept, so a run may go before rows already there); the tables' triggers (GDAL's feature-count triggers)
/// are taken off while the rows go in and put back after, each table's feature count and extent (gpkg_contents:
/// the slices' extents) set once. Throws sqlite::Failure; the caller removes `dst` then.
void append_runs(const std::string& dst, const std::vector<AppendRun>& runs);

/// A dataset whose plans layer serves the plans [first, last) only (and the other layers whole); the callee
/// closes it with GDALClose.
using SliceSource = std::function<GDALDatasetH(std::size_t first, std::size_t last)>;
/// Runs GDAL's ogr2ogr (the CLI's vector_translate): false on failure, GDAL having said why.
using Translate = std::function<bool(const std::string& dst, GDALDatasetH src, const std::vector<std::string>& args,
                                     bool progress, int* usage_error)>;

struct SliceWrite {
  std::string dst;                  // a GeoPackage that does not exist yet
  std::vector<std::string> flags;   // ogr2ogr options, no layer names
  std::vector<std::string> layers;  // what slice 0 writes (the plans layer among them)
  std::string plans_layer = "ground_plans";
  std::size_t plans = 0;            // features of the plans layer
  int writers = 2;
  bool progress = false;            // slice 0 reports progress
};

struct SliceOutcome {
  bool ok = false;
  int usage_error = 0;
  std::string error;                // non-empty: what failed (the destination has been removed)
  double slices_s = 0, merge_s = 0;  // writing the slices side by side; appending them to the destination
};

/// Writes `w.dst` with `w.writers` writers side by side (see above). On failure nothing is left under
/// `w.dst` nor beside it.
SliceOutcome write_gpkg_slices(const SliceWrite& w, const SliceSource& source, const Translate& translate);

/// The slices' common step: slice k of the plans layer (of w.writers, in plan order) written to paths[k] by its
/// own ogr2ogr, all side by side, slice 0 with w.layers (and the progress), the others with the plans layer alone;
/// `extra`: options added to w.flags. Sets out.slices_s and out.usage_error; false when a slice failed.
bool write_slices_side_by_side(const SliceWrite& w, const SliceSource& source, const Translate& translate,
                               const std::vector<std::string>& paths, const std::vector<std::string>& extra,
                               SliceOutcome& out);

/// Where slice k of a new `dst` is written: dst itself for k = 0, the others hidden beside it
/// (".<stem>.slice<k>-<pid><ext>").
std::string slice_path(const std::string& dst, std::size_t k, const std::string& ext);

/// Where the `writers` slices of a new `dst` are written: dst itself for slice 0, the others hidden beside it
/// (".<stem>.slice<k>-<pid><ext>").
std::vector<std::string> slice_paths(const std::string& dst, int writers, const std::string& ext);

/// Which plans layer slice [first, last) of `plans` in `writers` is: k's share is plans * k / writers onwards.
std::size_t slice_start(std::size_t plans, int k, int writers);

/// How many writers a plans layer of `plans` features gets on `threads` threads (the same rule for every format
/// written in slices); 1 and `why_one` when fewer than two.
int writers_for(std::size_t plans, int threads, std::string* why_one);

}  // namespace groundplan::output

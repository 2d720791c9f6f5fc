// SPDX-License-Identifier: MIT
#pragma once
// Stages 1-3 for one input file (read, georeference, footprints), self-contained so that files, and
// chunks of one CityGML file, are read side by side (issue 14). The pipeline merges the FileReads in
// file order; each is exactly what reading that file alone, one building after the other, gives.
#include <groundplan/footprint.h>
#include <groundplan/gis/crs.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/progress.h>
#include <groundplan/types.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace groundplan::gis::detail {

/// What one file's reading depends on from the files read before it. Fixed once a working CRS is
/// known (then later files are read side by side); before that the files are read one by one.
struct ReadContext {
  std::string working_definition;  // -t_srs, or the first georeferenced file's working CRS
  std::string unknown_frame_file;  // a file read before without CRS (georeferenced files cannot join it)
  /// run_pipeline: a georeferenced file read after files without CRS fixes the working CRS and those files are
  /// set aside (set_aside_files_without_crs), as they are when read after it: the outcome does not depend on the
  /// files' order. False (the tiled run, whose tiles are united as they are read): the georeferenced file fails.
  bool georeferenced_wins = false;
};

/// Why a file without CRS cannot join georeferenced inputs: `cause` ("it has no srsName" ...), the working CRS
/// `crs` ("EPSG:21781"). For the file's NO_CRS problem.
std::string no_crs_reason(const std::string& file, const std::string& cause, const std::string& crs);
/// `cause` for a file whose CRS (srsName, an OGR layer's CRS, -s_srs) `srs` is unknown: none, local or not one PROJ
/// places.
std::string no_crs_cause(const std::string& srs);

/// One file's outcome, merged into the PipelineResult in file order.
struct FileRead {
  std::vector<Footprint> footprints;  // in reading order
  std::vector<Problem> problems;      // in reading order, each footprint's problem where it was made, notes last
  std::size_t buildings_read = 0, buildings_dropped = 0;
  bool failed = false;                // the file could not be read (or not to its end): an UNREADABLE_FILE problem
  std::string failure;                // its message
  // CRS facts the pipeline needs (in file order) to fix the working CRS for the files after it.
  bool delivered = false;             // a mesh came out
  bool in_working_crs = false;        // KML / glTF: placed by the reader
  WorkingCrs reader_crs;              // their working CRS
  bool has_frame = false;             // CityGML: a WorkingFrame was made
  bool frame_source_known = false;
  std::string frame_srs;              // the CRS the frame was made from, as written (empty: none)
  std::vector<std::string> files_opened;  // the file and what the readers opened for it (files_read.h)
  WorkingCrs frame_crs;
  // How it was read (--stats).
  std::size_t chunks = 0;             // > 0: CityGML read in this many chunks side by side
  std::string whole_reason;           // CityGML read whole although cutting was asked for: why
  std::string xml_streamed_why;       // CityGML streamed through expat (some or all of it), not parsed in memory: why
  double footprint_wait_s = 0;        // read whole: the wait for its footprints after its last byte
};

/// Bytes read across all files, for -progress: reported from any thread, a few hundred times at most.
class ByteProgress {
 public:
  ByteProgress(Progress progress, std::uint64_t total_bytes) : progress_(std::move(progress)), total_(total_bytes) {}
  void add(std::uint64_t n);  // throws Cancelled when the user cancels
 private:
  Progress progress_;
  std::uint64_t total_;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::uint64_t> next_report_{0};
  std::mutex mutex_;
};

/// Reads one file (a CityGML file of at least two chunks in chunks side by side, unless
/// options.read_chunk_bytes < 0). `shared_bytes`: the bytes read side by side with this file on the
/// `threads` threads (the file's own size when it is read alone, every file left when files are read
/// side by side): automatic chunks are sized from it, so that a folder of many tiles is not cut finer
/// than its threads need. Never throws for the file's content (a failure is in FileRead); throws Cancelled.
FileRead read_file(const std::string& file, const PipelineOptions& options, const ReadContext& context,
                   std::size_t threads, std::uint64_t shared_bytes, ByteProgress& bytes);

/// The working CRS that reading `file` first (with `context`, which fixes none yet) will fix, found from its first
/// building alone: a CityGML file's first chunk, any other file's reading stopped at its first building. Lets every
/// file be read side by side with the first instead of after it (a folder of tiles: the first tile is no longer read
/// alone; over MPI ranks, the others no longer wait for it). Empty when that building does not decide it (no CRS
/// known, a reader that places the meshes itself, an unreadable start): then the first file is read before the
/// others, as always. A guess: the caller checks it against what the first file's reading fixed (fixed_crs).
std::string guess_working_definition(const std::string& file, const PipelineOptions& options, const ReadContext& context);

}  // namespace groundplan::gis::detail

// SPDX-License-Identifier: MIT
#pragma once
// The tiled run's temporary file (issue 15): each tile plan with its member footprints, written once by the
// map, read back by the reduce (a seam's footprints) and by the output layers (a final plan), from any thread.
#include <groundplan/types.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace groundplan::gis::detail {

/// One tile plan as stored: its members are global footprint indices, `footprints` the members themselves.
struct SpilledPlan {
  GroundPlan plan;
  std::vector<std::uint32_t> ids;      // = plan.members (global indices), kept apart for clarity when reduced
  std::vector<Footprint> footprints;   // the members, same order (polygons left empty when not asked for)
  std::uint32_t tile = 0;
  std::array<double, 4> box{};         // xmin, ymin, xmax, ymax of the plan's outer ring
};

/// An unnamed temporary file (created in GDAL's CPL_TMPDIR, else TMPDIR, else /tmp, and unlinked at once, so
/// nothing is left behind if the process dies). Appends are single-threaded; reads are positional (pread) and
/// may run on several threads at once.
class PlanSpill {
 public:
  PlanSpill();
  ~PlanSpill();
  PlanSpill(const PlanSpill&) = delete;
  PlanSpill& operator=(const PlanSpill&) = delete;

  /// Appends a plan (members: global indices, ascending) and its member footprints (`members[k]` is the
  /// footprint of plan.members[k]). Returns the record's offset. Throws Error when the disk refuses.
  std::uint64_t append(const GroundPlan& plan, const std::vector<const Footprint*>& members, std::uint32_t tile,
                       const std::array<double, 4>& box);
  /// Appends one record as encode() made it (length prefix included), e.g. one received from another rank.
  /// Returns its offset.
  std::uint64_t append_encoded(const char* record, std::size_t n);
  /// Writes what is buffered; call before reading.
  void flush();
  /// The record at `offset`; `next` (optional) gets the offset of the one after it. With `polygons` false the
  /// member footprints carry everything but their polygons. Throws Error on a short read.
  SpilledPlan read(std::uint64_t offset, bool polygons, std::uint64_t* next = nullptr) const;
  /// The record append() writes (length prefix first), added to `out`: what ranks send each other.
  static void encode(const GroundPlan& plan, const std::vector<const Footprint*>& members, std::uint32_t tile,
                     const std::array<double, 4>& box, std::vector<char>& out);
  /// The records in `bytes` (a run of encode()d records), decoded one by one. Throws Error when cut short.
  static std::vector<SpilledPlan> decode_all(const std::vector<char>& bytes, bool polygons);
  /// Length of the record starting at `p` (prefix included), checked against `left` bytes. Throws Error.
  static std::size_t record_length(const char* p, std::size_t left);
  /// Offset past the last record (bytes written).
  std::uint64_t size() const { return size_; }
  const std::string& directory() const { return dir_; }

 private:
  int fd_ = -1;
  std::string dir_;
  std::uint64_t size_ = 0;      // bytes appended (written + buffered)
  std::uint64_t written_ = 0;   // bytes on disk
  std::vector<char> buffer_;
};

}  // namespace groundplan::gis::detail

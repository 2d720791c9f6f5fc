// SPDX-License-Identifier: MIT
#pragma once
// -progress for a gzip input, in its compressed bytes (issue 16). The progress total counts a file's
// size on disk, the packed size for a .gz, but GDAL's /vsigzip/ tells a reader only the unpacked bytes
// it has read. GzipProgress turns those into packed bytes: unpacked * packed / ISIZE, ISIZE being the
// unpacked size the gzip trailer states (its last four bytes: the size mod 2^32 of the last member).
// For one member under 4 GiB that is the file's unpacked size, and the count moves with the packed
// bytes read as far as a deflate stream is uniform; otherwise (several members, 4 GiB or more, a trailer
// that lies) the count stops one byte short of the packed size until finish(). The count reported is
// never more than the packed size and reaches it exactly at finish().
#include <cpl_vsi.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>

namespace groundplan::gis {

class GzipProgress {
 public:
  /// `gz_path`: the .gz file itself (no /vsigzip/ prefix). `on_packed` is told packed bytes; may be empty.
  GzipProgress(const std::string& gz_path, std::function<void(std::uint64_t)> on_packed)
      : on_packed_(std::move(on_packed)) {
    VSIStatBufL st;
    if (VSIStatL(gz_path.c_str(), &st) != 0 || st.st_size < 18) return;  // 18: the smallest gzip file
    packed_ = static_cast<std::uint64_t>(st.st_size);
    if (VSILFILE* f = VSIFOpenL(gz_path.c_str(), "rb")) {
      unsigned char tail[4] = {0, 0, 0, 0};
      if (VSIFSeekL(f, packed_ - 4, SEEK_SET) == 0 && VSIFReadL(tail, 1, 4, f) == 4)
        isize_ = std::uint64_t{tail[0]} | std::uint64_t{tail[1]} << 8 | std::uint64_t{tail[2]} << 16 |
                 std::uint64_t{tail[3]} << 24;
      VSIFCloseL(f);
    }
  }

  /// `n` more unpacked bytes were read.
  void unpacked(std::uint64_t n) {
    unpacked_ += n;
    if (!on_packed_ || !isize_ || packed_ < 2) return;
    const double scaled = static_cast<double>(unpacked_) / static_cast<double>(isize_) * static_cast<double>(packed_);
    const std::uint64_t at = std::min(packed_ - 1, static_cast<std::uint64_t>(std::max(0.0, scaled)));
    tell(at);
  }

  /// The whole file was read: the count becomes the packed size.
  void finish() { tell(packed_); }

  std::uint64_t packed_size() const { return packed_; }

 private:
  void tell(std::uint64_t at) {
    if (at <= told_ || !on_packed_) return;
    on_packed_(at - told_);
    told_ = at;
  }

  std::function<void(std::uint64_t)> on_packed_;
  std::uint64_t packed_ = 0, isize_ = 0, unpacked_ = 0, told_ = 0;
};

}  // namespace groundplan::gis

// SPDX-License-Identifier: MIT
#pragma once
// What the ranks of a tiled run (issue 15 stage 2) agree on and send each other besides plan records: which
// input files each rank maps (contiguous runs balanced by bytes), and a flat byte form for counts and problems.
#include <groundplan/types.h>

#include "pipeline/byte_reader.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace groundplan::gis::detail {

/// Cuts files [0, n) into `ranks` contiguous runs of about equal bytes: rank r maps [bounds[r], bounds[r+1]).
/// Each cut is the file boundary nearest to r/ranks of the bytes, kept so that every rank gets a file where there
/// are as many files as ranks. Files [0, first_free) are rank 0's whatever their size (it read them to fix the
/// working CRS). Deterministic: the same sizes give the same cut on every rank. With fewer files than ranks, some
/// ranks get none.
std::vector<std::size_t> split_by_bytes(const std::vector<std::uint64_t>& sizes, int ranks, std::size_t first_free);

/// Appends plain values and strings to a byte vector (host layout: ranks run on one architecture).
class Packer {
 public:
  template <class T>
  void put(const T& v) {
    const char* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void str(const std::string& s);
  void problems(const std::vector<Problem>& list);
  std::vector<char> bytes;
};

/// Reads what a Packer wrote, in the same order; throws Error when the bytes run out.
class Unpacker : public ByteReader {
 public:
  Unpacker(const char* p, std::size_t n)
      : ByteReader(p, n, "tiled run over ranks: a message from another rank is cut short") {}
  std::string str() { return ByteReader::str<std::uint64_t>(); }
  /// Appends the problems to `out`.
  void problems(std::vector<Problem>& out);
};

}  // namespace groundplan::gis::detail

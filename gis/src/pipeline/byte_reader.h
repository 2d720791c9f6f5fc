// SPDX-License-Identifier: MIT
#pragma once
// Reading back plain values and length-prefixed strings from bytes written in host layout: the tiled run's
// temporary plan records (plan_spill.cpp) and the messages between the ranks of an MPI run (tile_ranks.h).
// Both live only as long as the run, on hosts of one architecture.
#include <groundplan/error.h>

#include <cstring>
#include <string>

namespace groundplan::gis::detail {

class ByteReader {
 public:
  /// `short_message`: the Error thrown when the bytes run out before a value does.
  ByteReader(const char* p, std::size_t n, const char* short_message) : p_(p), end_(p + n), short_(short_message) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  /// A string written as its length (a `Length`) and its bytes.
  template <class Length>
  std::string str() {
    const auto n = static_cast<std::size_t>(get<Length>());
    need(n);
    std::string s(p_, n);
    p_ += n;
    return s;
  }
  bool done() const { return p_ == end_; }

 protected:
  void need(std::size_t n) const {
    if (static_cast<std::size_t>(end_ - p_) < n) throw Error(short_);
  }
  const char* p_;
  const char* end_;

 private:
  const char* short_;
};

}  // namespace groundplan::gis::detail

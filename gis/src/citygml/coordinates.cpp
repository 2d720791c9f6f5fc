// SPDX-License-Identifier: MIT
#include "citygml/coordinates.h"

#include "citygml/decimal.h"

#include <charconv>
#include <cmath>
#include <string>

namespace groundplan::gis::detail {
namespace {

inline bool is_space(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r'; }

/// `fast`: try parse_decimal's fast path; cleared once a number of the list needed from_chars (the
/// numbers of one list are written alike). Both give the same double.
inline CoordStatus parse_one(const char*& p, const char* end, std::vector<double>& out, bool& fast) {
  if (*p == '+') ++p;  // from_chars refuses a leading '+'; xs:double allows it
  double v;
  bool slow = false;
  auto [next, ec] = fast ? parse_decimal(p, end, v, &slow) : std::from_chars(p, end, v);
  if (slow) fast = false;
  if (ec != std::errc() || (next != end && !is_space(*next))) {
    if (ec == std::errc::result_out_of_range) return CoordStatus::NotFinite;
    return CoordStatus::BadNumber;
  }
  if (!std::isfinite(v)) return CoordStatus::NotFinite;
  out.push_back(v);
  p = next;
  return CoordStatus::Ok;
}

}  // namespace

CoordStatus parse_numbers(std::string_view text, std::vector<double>& out) {
  const char* p = text.data();
  const char* end = p + text.size();
  bool fast = true;
  for (;;) {
    while (p < end && is_space(*p)) ++p;
    if (p == end) return CoordStatus::Ok;
    CoordStatus s = parse_one(p, end, out, fast);
    if (s != CoordStatus::Ok) return s;
  }
}

CoordStatus parse_gml_coordinates(std::string_view text, char cs, char ts, char decimal, std::vector<double>& out,
                                  int& dim) {
  // Normalise into "a b c a b c": value separators and tuple separators both become spaces, counting
  // values per tuple on the way.
  std::string buf(text);
  dim = -1;
  int in_tuple = 0;
  bool in_value = false;
  auto end_tuple = [&] {
    if (in_value) { ++in_tuple; in_value = false; }
    if (in_tuple > 0) {
      if (dim < 0) dim = in_tuple;
      else if (dim != in_tuple) dim = 0;
    }
    in_tuple = 0;
  };
  const bool ts_space = ts == ' ';
  for (char& c : buf) {
    if (c == cs) {
      if (in_value) { ++in_tuple; in_value = false; }
      c = ' ';
    } else if (c == ts || (ts_space && is_space(c))) {
      end_tuple();
      c = ' ';
    } else if (is_space(c)) {
      // whitespace around separators is tolerated
    } else {
      if (c == decimal) c = '.';
      in_value = true;
    }
  }
  end_tuple();
  if (dim < 0) dim = 0;
  return parse_numbers(buf, out);
}

int infer_dimension(const std::vector<double>& v, std::size_t first, int fallback) {
  const std::size_t n = v.size() - first;
  auto closes = [&](std::size_t d) {
    if (n % d != 0 || n < 4 * d) return false;
    for (std::size_t k = 0; k < d; ++k)
      if (v[first + k] != v[first + n - d + k]) return false;
    return true;
  };
  if (closes(3)) return 3;
  if (closes(2)) return 2;
  if (fallback == 2 && n % 2 == 0) return 2;
  if (n % 3 == 0) return 3;
  if (n % 2 == 0) return 2;
  return fallback;
}

}  // namespace groundplan::gis::detail

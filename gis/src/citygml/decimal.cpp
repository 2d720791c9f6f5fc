// SPDX-License-Identifier: MIT
#include "citygml/decimal.h"

namespace groundplan::gis::detail {
namespace {

// 10^0 .. 10^22: every one exactly representable as a double.
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

inline bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

}  // namespace

std::from_chars_result parse_decimal(const char* p, const char* end, double& v, bool* slow) {
  // From here on, every way out but the last is from_chars deciding.
  auto fallback = [&] {
    if (slow) *slow = true;
    return std::from_chars(p, end, v);
  };
  const char* s = p;
  const bool negative = s < end && *s == '-';
  if (negative) ++s;
  // Every digit, leading zeros too, goes into m: 19 digits always fit in 64 bits; a longer mantissa
  // (rare in coordinates) takes from_chars' path.
  std::uint64_t m = 0;
  const char* first = s;
  while (s < end && is_digit(*s)) m = m * 10 + static_cast<unsigned>(*s++ - '0');
  std::ptrdiff_t digits = s - first;
  int exponent = 0;  // decimal exponent of m's last digit
  if (s < end && *s == '.') {
    const char* frac = ++s;
    while (s < end && is_digit(*s)) m = m * 10 + static_cast<unsigned>(*s++ - '0');
    exponent = -static_cast<int>(s - frac);
    digits += s - frac;
  }
  // No digit ("inf", "nan", ".", "-", garbage) or too many: from_chars decides.
  if (digits == 0 || digits > 19) return fallback();
  if (s < end && (*s == 'e' || *s == 'E')) {
    const char* e = s + 1;
    bool eneg = false;
    if (e < end && (*e == '-' || *e == '+')) eneg = *e++ == '-';
    if (e == end || !is_digit(*e)) return fallback();  // "1e", "1e+": from_chars decides
    int x = 0;
    for (; e < end && is_digit(*e); ++e) {
      if (x > 10000) return fallback();
      x = x * 10 + (*e - '0');
    }
    exponent += eneg ? -x : x;
    s = e;
  }
  if (m > (std::uint64_t{1} << 53) || exponent < -22 || exponent > 22) return fallback();
  double d = static_cast<double>(m);  // exact: m <= 2^53
  d = exponent < 0 ? d / kPow10[-exponent] : d * kPow10[exponent];
  v = negative ? -d : d;
  return {s, std::errc()};
}

}  // namespace groundplan::gis::detail

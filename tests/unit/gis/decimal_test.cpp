// SPDX-License-Identifier: MIT
// parse_decimal (issue 14): the posList number parser's fast path against strtod, bit for bit, on
// random decimal strings (short and long mantissas, exponents near and far), and against
// std::from_chars on where a number ends and on what is refused.
#include <gtest/gtest.h>

#include "citygml/coordinates.h"
#include "citygml/decimal.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace groundplan::gis::detail {
namespace {

std::uint64_t bits(double d) {
  std::uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return b;
}

/// parse_decimal and from_chars agree on the end and the error; where both parse, strtod gives the
/// same bits.
void expect_same(const std::string& s) {
  double ours = -12345.0, ref = -12345.0;
  const auto a = parse_decimal(s.data(), s.data() + s.size(), ours);
  const auto b = std::from_chars(s.data(), s.data() + s.size(), ref);
  ASSERT_EQ(a.ec, b.ec) << "\"" << s << "\"";
  ASSERT_EQ(a.ptr - s.data(), b.ptr - s.data()) << "\"" << s << "\"";
  if (a.ec != std::errc()) return;
  // strtod on the number from_chars found (strtod alone would also read "0x10" as hex)
  const std::string number = s.substr(0, static_cast<std::size_t>(a.ptr - s.data()));
  char* e = nullptr;
  const double c = std::strtod(number.c_str(), &e);
  ASSERT_EQ(static_cast<std::size_t>(e - number.c_str()), number.size()) << "\"" << s << "\"";
  if (std::isnan(c)) {
    EXPECT_TRUE(std::isnan(ours)) << "\"" << s << "\"";
  } else {
    EXPECT_EQ(bits(ours), bits(c)) << "\"" << s << "\": ours " << ours << ", strtod " << c;
  }
}

std::string digits(std::mt19937_64& rng, int n, bool nonzero_first) {
  std::string s;
  for (int k = 0; k < n; ++k) {
    char c = static_cast<char>('0' + rng() % 10);
    if (k == 0 && nonzero_first && c == '0') c = '1';
    s += c;
  }
  return s;
}

TEST(Decimal, EdgeCases) {
  for (const char* s :
       {"0", "-0", "0.0", "-0.0", ".5", "5.", "-.5", "00012.500", "1e22", "1e23", "9007199254740992", "9007199254740993",
        "9007199254740993.0", "1234567890123456789", "12345678901234567890", "0.1", "0.3", "2.2250738585072014e-308",
        "4.9e-324", "1.7976931348623157e308", "1e-22", "1e-23", "123e-20", "406143.676", "5863437.505", "-38.102",
        "1e", "1e+", "1e-", "1E5", "1.5E-3", "inf", "-inf", "nan", "infinity", "-", ".", "-.", "abc", "", "1.2.3",
        "12a", "1e5x", "0x10", "1e400", "1e-400", "0e999999", "1e0000000000000000000001", "+1"})
    expect_same(s);
}

TEST(Decimal, RandomAgainstStrtod) {
  std::mt19937_64 rng(14);
  for (int i = 0; i < 300000; ++i) {
    std::string s;
    if (rng() % 2) s += '-';
    const int shape = static_cast<int>(rng() % 4);
    if (shape == 0) {  // posList-like: 1-7 integer digits, 0-4 decimals
      s += digits(rng, 1 + static_cast<int>(rng() % 7), true);
      if (rng() % 4) {
        s += '.';
        s += digits(rng, static_cast<int>(rng() % 5), false);
      }
    } else {  // any length of mantissa, up to 25 + 25 digits, leading zeros possible
      s += digits(rng, static_cast<int>(rng() % 26), false);
      if (rng() % 2) {
        s += '.';
        s += digits(rng, static_cast<int>(rng() % 26), false);
      }
      if (s.empty() || s == "-" || s.back() == '.' || s == "-.") s += digits(rng, 1, false);
    }
    if (shape >= 2) {  // an exponent, near (fast path) or far (fallback)
      s += (rng() % 2) ? 'e' : 'E';
      const int r = static_cast<int>(rng() % 3);
      if (r == 1) s += '-';
      else if (r == 2) s += '+';
      s += std::to_string(shape == 2 ? rng() % 30 : rng() % 340);
    }
    expect_same(s);
    if (HasFatalFailure() || HasFailure()) return;
  }
}

TEST(Decimal, ExactFastPathValues) {
  // m x 10^e with m < 2^53, |e| <= 22: built from integers, compared with strtod.
  std::mt19937_64 rng(1414);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t m = rng() % (std::uint64_t{1} << 53);
    const int e = static_cast<int>(rng() % 45) - 22;
    const std::string s = std::to_string(m) + "e" + std::to_string(e);
    expect_same(s);
    if (HasFailure()) return;
  }
}

TEST(Decimal, ListsMixingShortAndLongNumbersParseAsStrtodDoes) {
  // parse_numbers leaves the fast path for the rest of a list once a number needs from_chars
  // (17 significant digits, as in some PLATEAU longitudes): every number still comes out as strtod reads it.
  std::mt19937_64 rng(6697);
  for (int i = 0; i < 2000; ++i) {
    std::string list;
    std::vector<double> want;
    const int n = 1 + static_cast<int>(rng() % 12);
    for (int k = 0; k < n; ++k) {
      std::string num = (rng() % 3 == 0) ? "139." + digits(rng, 14, false) : digits(rng, 1 + static_cast<int>(rng() % 6), true) + "." + digits(rng, 3, false);
      if (rng() % 4 == 0) num = "-" + num;
      want.push_back(std::strtod(num.c_str(), nullptr));
      list += num;
      list += (rng() % 2) ? " " : "\n\t";
    }
    std::vector<double> got;
    ASSERT_EQ(parse_numbers(list, got), CoordStatus::Ok) << list;
    ASSERT_EQ(got.size(), want.size()) << list;
    for (std::size_t k = 0; k < got.size(); ++k) ASSERT_EQ(bits(got[k]), bits(want[k])) << list << " #" << k;
  }
}

}  // namespace
}  // namespace groundplan::gis::detail

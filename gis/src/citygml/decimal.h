// SPDX-License-Identifier: MIT
#pragma once
// Decimal numbers as gml:posList writes them (issue 14: the reader's speed per core). The common case,
// at most 19 significant digits and a value exactly m x 10^e with m < 2^53 and |e| <= 22, is one IEEE
// multiplication or division of two exact doubles, so correctly rounded (Clinger's fast path, as in
// strtod and fast_float); everything else goes to std::from_chars, which rounds correctly too.
#include <charconv>
#include <cstdint>

namespace groundplan::gis::detail {

/// Parses a number at [p, end) as std::from_chars(p, end, v) does (no leading '+', no hex, "inf"/"nan"
/// accepted) and gives the same result: ptr past the number, ec as from_chars sets it. `slow`, when
/// given, is set when the number needed from_chars (a 17-digit latitude does): a caller with a list of
/// such numbers then calls from_chars itself, not paying the fast path's attempt on each.
std::from_chars_result parse_decimal(const char* p, const char* end, double& v, bool* slow = nullptr);

}  // namespace groundplan::gis::detail

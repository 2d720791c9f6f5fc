// SPDX-License-Identifier: MIT
#pragma once
// Number parsing for gml:posList, gml:pos and gml:coordinates (issue 6). parse_decimal (decimal.h): no
// locale, no allocation, correctly rounded like strtod.
#include <cstddef>
#include <string_view>
#include <vector>

namespace groundplan::gis::detail {

enum class CoordStatus { Ok, BadNumber, NotFinite };

/// Appends every whitespace-separated number of `text` to `out`. On a bad token stops and returns
/// BadNumber (out then holds the numbers before it); NaN/Inf give NotFinite.
CoordStatus parse_numbers(std::string_view text, std::vector<double>& out);

/// gml:coordinates: tuples separated by `ts` (default whitespace), values by `cs` (default ','),
/// `decimal` the decimal mark. Appends the numbers to `out` and returns the tuple dimension found
/// in `dim` (0 when the tuples disagree).
CoordStatus parse_gml_coordinates(std::string_view text, char cs, char ts, char decimal, std::vector<double>& out,
                                  int& dim);

/// srsDimension of a posList that has none: 3 or 2, chosen so that the ring closes (first point ==
/// last point), else the one that divides the count (3 preferred), else `fallback`.
int infer_dimension(const std::vector<double>& values, std::size_t first, int fallback);

}  // namespace groundplan::gis::detail

// SPDX-License-Identifier: MIT
// The coordinate text parsers of the CityGML reader (posList/pos and gml:coordinates with cs, ts,
// decimal) on arbitrary text (issue 8): never crash, only finite numbers come out.
#include "fuzz_entry.h"

#include "citygml/coordinates.h"

#include <cmath>
#include <string_view>
#include <vector>

GROUNDPLAN_FUZZ_TARGET(coordinates) {
  using namespace groundplan::gis::detail;
  if (size < 3) return 0;
  const char cs = static_cast<char>(data[0]), ts = static_cast<char>(data[1]), dec = static_cast<char>(data[2]);
  const std::string_view text(reinterpret_cast<const char*>(data + 3), size - 3);
  std::vector<double> v;
  if (parse_numbers(text, v) == CoordStatus::Ok)
    for (double x : v)
      if (!std::isfinite(x)) groundplan_fuzz_fail("coordinates", "parse_numbers gave a non-finite number");
  v.clear();
  int dim = 0;
  if (parse_gml_coordinates(text, cs, ts, dec, v, dim) == CoordStatus::Ok) {
    for (double x : v)
      if (!std::isfinite(x)) groundplan_fuzz_fail("coordinates", "parse_gml_coordinates gave a non-finite number");
    if (dim < 0) groundplan_fuzz_fail("coordinates", "negative dimension");
  }
  if (!v.empty()) {
    const int d = infer_dimension(v, 0, 3);
    if (d <= 0) groundplan_fuzz_fail("coordinates", "infer_dimension gave no dimension");
  }
  return 0;
}

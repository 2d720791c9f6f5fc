// SPDX-License-Identifier: MIT
// srsName parsing on arbitrary text (issue 8): never crashes, and what it says is consistent.
#include "fuzz_entry.h"

#include <groundplan/gis/crs.h>

#include <string_view>

GROUNDPLAN_FUZZ_TARGET(srs_name) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const groundplan::gis::SrsName s = groundplan::gis::parse_srs_name(text);
  if (s.text != text) groundplan_fuzz_fail("srs_name", "text is not kept as written");
  if (s.epsg < 0 || s.vertical_epsg < 0) groundplan_fuzz_fail("srs_name", "negative EPSG code");
  if (s.local && !s.definition.empty()) groundplan_fuzz_fail("srs_name", "a local CRS with a PROJ definition");
  if (s.epsg && s.definition != "EPSG:" + std::to_string(s.epsg))
    groundplan_fuzz_fail("srs_name", "EPSG code and definition disagree");
  return 0;
}

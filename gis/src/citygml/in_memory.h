// SPDX-License-Identifier: MIT
#pragma once
// How large a CityGML document the pipeline parses in memory (citygml.h dom_max_bytes): GDAL's config
// option GROUNDPLAN_XML_IN_MEMORY_BYTES (`--config GROUNDPLAN_XML_IN_MEMORY_BYTES 0` streams every file
// through expat, the reader before issue 14's pugixml path; the result is the same), else the default.
#include <groundplan/gis/citygml.h>

#include <cpl_conv.h>

#include <cstdlib>

namespace groundplan::gis::citygml {

inline std::size_t in_memory_bytes() {
  const char* v = CPLGetConfigOption("GROUNDPLAN_XML_IN_MEMORY_BYTES", nullptr);
  if (!v || !*v) return CityGmlOptions{}.dom_max_bytes;
  char* end = nullptr;
  const unsigned long long n = std::strtoull(v, &end, 10);
  return end && *end == 0 ? static_cast<std::size_t>(n) : CityGmlOptions{}.dom_max_bytes;
}

}  // namespace groundplan::gis::citygml

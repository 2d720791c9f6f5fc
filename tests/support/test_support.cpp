// SPDX-License-Identifier: MIT
#include "test_support.h"

#include "test_config.h"

#include <groundplan/gis/geos_reference.h>

namespace groundplan::test {

std::string shared_data(const std::string& relative) { return std::string(GROUNDPLAN_SHARED_DATA_DIR) + "/" + relative; }
std::string sample_data(const std::string& relative) { return std::string(GROUNDPLAN_SAMPLE_DATA_DIR) + "/" + relative; }

std::vector<Footprint> footprints_from_wkt(const std::vector<std::string>& wkts) {
  std::vector<Footprint> out;
  for (std::size_t i = 0; i < wkts.size(); ++i) {
    Footprint f;
    f.polygons = gis::polygons_from_wkt(wkts[i]);
    f.source_id = "f" + std::to_string(i);
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace groundplan::test

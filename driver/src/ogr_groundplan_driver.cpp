// SPDX-License-Identifier: MIT
// Plugin entry point. GDAL derives the symbol name RegisterOGRGroundPlan from the file name ogr_GroundPlan.so.
#include "ogr_groundplan.h"

extern "C" __attribute__((visibility("default"))) void RegisterOGRGroundPlan() {
  if (!GDAL_CHECK_VERSION("GroundPlan")) return;
  groundplan::driver::register_driver();
}

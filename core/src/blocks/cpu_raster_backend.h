// SPDX-License-Identifier: MIT
#pragma once
// CPU raster backend (paper §5 blocks, §3 Update seeds).
#include <groundplan/raster_backend.h>

namespace groundplan::detail {

class CpuRasterBackend final : public RasterBackend {
 public:
  const char* name() const override { return "cpu"; }
  std::vector<Block> find_blocks(const FootprintSet& fps, const PixelGrid& grid, const Progress& progress) override;
  Seeds find_new_seeds(const FootprintSet& fps, const Block& block, const std::vector<GroundPlan>& so_far,
                       const PixelGrid& grid) override;
};

}  // namespace groundplan::detail

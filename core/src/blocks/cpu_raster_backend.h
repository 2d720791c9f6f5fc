// SPDX-License-Identifier: MIT
#pragma once
// CPU raster backend (paper §5 blocks, §3 Update seeds).
#include <groundplan/raster_backend.h>

#include <cstdint>

namespace groundplan::detail {

class CpuRasterBackend final : public RasterBackend {
 public:
  /// band_keys: the most (pixel, label) keys made and sorted at once (8 bytes each); rows are
  /// processed in bands of at most that many keys (a single row is never split).
  explicit CpuRasterBackend(std::uint64_t band_keys = std::uint64_t{1} << 24) : band_keys_(band_keys) {}
  const char* name() const override { return "cpu"; }
  std::vector<Block> find_blocks(const FootprintSet& fps, const PixelGrid& grid, const Progress& progress) override;
  Seeds find_new_seeds(const FootprintSet& fps, const Block& block, const std::vector<GroundPlan>& so_far,
                       const PixelGrid& grid) override;

 private:
  std::uint64_t band_keys_;
};

}  // namespace groundplan::detail

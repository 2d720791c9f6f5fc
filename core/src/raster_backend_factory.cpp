// SPDX-License-Identifier: MIT
// The one place that chooses a raster backend (STYLE.md §6). The CUDA backend is issue 4: until it
// exists, asking for it is an error, and Auto means CPU.
#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include "blocks/cpu_raster_backend.h"

namespace groundplan {

std::unique_ptr<RasterBackend> make_raster_backend(Device requested) {
  switch (requested) {
    case Device::Cuda:
      throw GpuError("not built with CUDA: the CUDA raster backend is not available in this build; use --device cpu");
    case Device::Auto:
    case Device::Cpu:
      break;
  }
  return std::make_unique<detail::CpuRasterBackend>();
}

}  // namespace groundplan

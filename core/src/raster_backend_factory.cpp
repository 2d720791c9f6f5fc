// SPDX-License-Identifier: MIT
// The one place that chooses a raster backend (STYLE.md §6). Cuda: the CUDA backend from its module
// (blocks/cuda_raster_backend.h), or GpuError saying why when the module cannot be loaded or no device
// answers. Auto: CUDA when the module loads, a device answers and the work is large enough to pay for
// starting it (kCudaAutoMinFootprints), else CPU. Both give the same blocks and seeds.
#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include "blocks/cpu_raster_backend.h"
#include "blocks/cuda_raster_backend.h"

namespace groundplan {

std::unique_ptr<RasterBackend> make_raster_backend(Device requested, std::size_t footprints) {
  switch (requested) {
    case Device::Cuda:
      return detail::make_cuda_raster_backend();  // throws GpuError when the module or a device is missing
    case Device::Auto:
      // below the threshold the module is not even loaded
      if (footprints >= kCudaAutoMinFootprints && detail::cuda_device_count() > 0) {
        try {
          return detail::make_cuda_raster_backend();
        } catch (const GpuError&) {
          // a device that answers the count but cannot start a context: the CPU gives the same blocks
        }
      }
      break;
    case Device::Cpu:
      break;
  }
  return std::make_unique<detail::CpuRasterBackend>();
}

}  // namespace groundplan

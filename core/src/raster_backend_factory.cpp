// SPDX-License-Identifier: MIT
// The one place that chooses a raster backend (STYLE.md §6). Cuda: the CUDA backend from its module
// (blocks/cuda_raster_backend.h), or GpuError saying why when the module cannot be loaded or no device
// answers. Auto: the CPU: measured on a 16-core GPU host, the CPU finds the blocks of a 1.5 GB city in
// 0.06 s where the CUDA backend takes 0.33 s with its start (tests/bench/RESULTS.md), so no size was found
// where the GPU pays (and the module is never loaded for it). Both give the same blocks and seeds.
#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include "blocks/cpu_raster_backend.h"
#include "blocks/cuda_raster_backend.h"

namespace groundplan {

std::unique_ptr<RasterBackend> make_raster_backend(Device requested) {
  switch (requested) {
    case Device::Cuda:
      return detail::make_cuda_raster_backend();  // throws GpuError when the module or a device is missing
    case Device::Auto:
    case Device::Cpu:
      break;
  }
  return std::make_unique<detail::CpuRasterBackend>();
}

}  // namespace groundplan

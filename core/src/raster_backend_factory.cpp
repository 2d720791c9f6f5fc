// SPDX-License-Identifier: MIT
// The one place that chooses a raster backend and the only #ifdef GROUNDPLAN_HAVE_CUDA (STYLE.md
// §6). Cuda: the CUDA backend, or GpuError when it is not built in or no device answers. Auto: the CPU:
// measured on a 16-core GPU host, the CPU finds the blocks of a 1.5 GB city in 0.06 s where the CUDA
// backend takes 0.33 s with its start (tests/bench/RESULTS.md), so no size was found where the GPU pays.
// Both give the same blocks and seeds.
#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include "blocks/cpu_raster_backend.h"
#ifdef GROUNDPLAN_HAVE_CUDA
#include "blocks/cuda_raster_backend.h"
#endif

namespace groundplan {

std::unique_ptr<RasterBackend> make_raster_backend(Device requested) {
  switch (requested) {
    case Device::Cuda:
#ifdef GROUNDPLAN_HAVE_CUDA
      return detail::make_cuda_raster_backend();  // throws GpuError when no device answers
#else
      throw GpuError("not built with CUDA: the CUDA raster backend is not available in this build; use --device cpu");
#endif
    case Device::Auto:
    case Device::Cpu:
      break;
  }
  return std::make_unique<detail::CpuRasterBackend>();
}

}  // namespace groundplan

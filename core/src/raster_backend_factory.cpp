// SPDX-License-Identifier: MIT
// The one place that chooses a raster backend and the only #ifdef GROUNDPLAN_HAVE_CUDA (STYLE.md
// §6). Cuda: the CUDA backend, or GpuError when it is not built in or no device answers. Auto: CUDA
// when it is built in, a device answers and the work is large enough to pay for starting it
// (kCudaAutoMinFootprints), else CPU. Both give the same blocks and seeds.
#include <groundplan/error.h>
#include <groundplan/raster_backend.h>

#include "blocks/cpu_raster_backend.h"
#ifdef GROUNDPLAN_HAVE_CUDA
#include "blocks/cuda_raster_backend.h"
#endif

namespace groundplan {

std::unique_ptr<RasterBackend> make_raster_backend(Device requested, [[maybe_unused]] std::size_t footprints) {
  switch (requested) {
    case Device::Cuda:
#ifdef GROUNDPLAN_HAVE_CUDA
      return detail::make_cuda_raster_backend();  // throws GpuError when no device answers
#else
      throw GpuError("not built with CUDA: the CUDA raster backend is not available in this build; use --device cpu");
#endif
    case Device::Auto:
#ifdef GROUNDPLAN_HAVE_CUDA
      if (footprints >= kCudaAutoMinFootprints && detail::cuda_device_count() > 0) {
        try {
          return detail::make_cuda_raster_backend();
        } catch (const GpuError&) {
          // a device that answers the count but cannot start a context: the CPU gives the same blocks
        }
      }
#endif
      break;
    case Device::Cpu:
      break;
  }
  return std::make_unique<detail::CpuRasterBackend>();
}

}  // namespace groundplan

// SPDX-License-Identifier: MIT
#pragma once
// The CUDA raster backend's entry points, in plain C++ (STYLE.md §6): defined in
// gpu/src/cuda_raster_backend.cu, called only from core/src/raster_backend_factory.cpp inside its
// #ifdef GROUNDPLAN_HAVE_CUDA.
#include <groundplan/raster_backend.h>

#include <cstdint>
#include <memory>

namespace groundplan::detail {

/// Number of CUDA devices that answer; 0 when there is none or no usable driver (never throws).
int cuda_device_count();

/// The CUDA backend on device 0; throws GpuError when no device answers. band_keys bounds the
/// keys sorted at once on the device (16 bytes each with the sort's second buffer and labels).
std::unique_ptr<RasterBackend> make_cuda_raster_backend(std::uint64_t band_keys = std::uint64_t{1} << 26);

}  // namespace groundplan::detail

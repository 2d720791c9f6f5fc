// SPDX-License-Identifier: MIT
#pragma once
// The CUDA raster backend lives in a module of its own, libgroundplan_cuda.so.0 (gpu/), which core
// loads with dlopen the first time a CUDA backend is asked for (cuda_module.cpp). Nothing else of
// groundplan links the CUDA runtime, so the CLI, the GDAL plugin, libgroundplan and the Python module
// load on a machine without CUDA; the module itself links the CUDA runtime statically and needs only
// the NVIDIA driver when it runs. The module and the loader meet through CudaModuleApi, plain C++
// (STYLE.md §6).
#include <groundplan/raster_backend.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace groundplan::detail {

/// The module's file name, found like a shared library (the build tree's lib/ through the build
/// RUNPATH, else LD_LIBRARY_PATH and the system's library folders, where the package installs it).
inline constexpr const char* kCudaModuleFile = "libgroundplan_cuda.so.0";
/// Its one exported symbol: a function returning the module's CudaModuleApi.
inline constexpr const char* kCudaModuleEntry = "groundplan_cuda_module_api";

/// What the module gives the loader. `build` must equal the loader's GROUNDPLAN_CUDA_MODULE_BUILD
/// (version and compiler): RasterBackend crosses between them as a C++ object.
struct CudaModuleApi {
  const char* build;
  /// Number of CUDA devices that answer; 0 when there is none or no usable driver (never throws).
  int (*device_count)();
  /// A new backend on device 0, or nullptr with the reason in `error` (at most error_size bytes,
  /// NUL-terminated) when no device answers. band_keys bounds the keys sorted at once on the device.
  RasterBackend* (*make_backend)(std::uint64_t band_keys, char* error, std::size_t error_size);
};
using CudaModuleEntry = const CudaModuleApi* (*)();

/// The module's table, loaded once per process and kept; nullptr when it cannot be loaded, with the
/// reason (the file, dlerror's words or the build mismatch) in *why.
const CudaModuleApi* cuda_module(std::string* why);

/// Number of CUDA devices that answer; 0 without the module, a device or a usable driver.
int cuda_device_count();

/// The CUDA backend on device 0; throws GpuError saying why when the module cannot be loaded or no
/// device answers.
std::unique_ptr<RasterBackend> make_cuda_raster_backend(std::uint64_t band_keys = std::uint64_t{1} << 26);

}  // namespace groundplan::detail

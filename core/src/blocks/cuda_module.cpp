// SPDX-License-Identifier: MIT
// Loads the CUDA raster backend's module (cuda_raster_backend.h) once per process and never unloads
// it: backends it made may live as long as the process.
#include <dlfcn.h>
#include <groundplan/error.h>

#include <mutex>
#include <string>

#include "blocks/cuda_raster_backend.h"

#ifndef GROUNDPLAN_CUDA_MODULE_BUILD
#error "GROUNDPLAN_CUDA_MODULE_BUILD (version and compiler, core/CMakeLists.txt) must be defined"
#endif

namespace groundplan::detail {
namespace {

struct Loaded {
  const CudaModuleApi* api = nullptr;
  std::string why;
};

Loaded load() {
  Loaded r;
  void* handle = dlopen(kCudaModuleFile, RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* e = dlerror();
    r.why = std::string("the CUDA raster backend ") + kCudaModuleFile + " could not be loaded (" +
            (e ? e : "no reason given") +
            "); it is built and installed with groundplan where the CUDA toolkit is found at build time "
            "(-DGROUNDPLAN_CUDA=ON)";
    return r;
  }
  auto entry = reinterpret_cast<CudaModuleEntry>(dlsym(handle, kCudaModuleEntry));
  if (!entry) {
    r.why = std::string(kCudaModuleFile) + " has no " + kCudaModuleEntry + ": not a groundplan CUDA module";
    return r;
  }
  const CudaModuleApi* api = entry();
  if (!api || !api->build || std::string(api->build) != GROUNDPLAN_CUDA_MODULE_BUILD) {
    r.why = std::string(kCudaModuleFile) + " was built for groundplan " + (api && api->build ? api->build : "?") +
            ", this is " + GROUNDPLAN_CUDA_MODULE_BUILD + ": install the module of the same build";
    return r;
  }
  r.api = api;
  return r;
}

}  // namespace

const CudaModuleApi* cuda_module(std::string* why) {
  static const Loaded loaded = load();  // thread-safe once (C++11 static initialisation)
  if (!loaded.api && why) *why = loaded.why;
  return loaded.api;
}

int cuda_device_count() {
  const CudaModuleApi* api = cuda_module(nullptr);
  return api ? api->device_count() : 0;
}

std::unique_ptr<RasterBackend> make_cuda_raster_backend(std::uint64_t band_keys) {
  std::string why;
  const CudaModuleApi* api = cuda_module(&why);
  if (!api) throw GpuError(why + "; use --device cpu or --device auto");
  char error[512] = {};
  RasterBackend* backend = api->make_backend(band_keys, error, sizeof error);
  if (!backend) throw GpuError(std::string(error) + "; use --device cpu or --device auto");
  return std::unique_ptr<RasterBackend>(backend);
}

}  // namespace groundplan::detail

// SPDX-License-Identifier: MIT
// Blocks (paper §5) and Update seeds (§3) on the GPU, bit for bit the CPU backend's results
// (core/src/blocks/cpu_raster_backend.cpp), through the same functions (blocks/raster_common.h):
//
//  1. one thread per footprint: the pixel ranges of its box (pixel_index: IEEE double sub, div,
//     floor; --fmad=false), and its number of (pixel, label) keys inside the row band;
//  2. exclusive scan of the counts (CUB), one thread per footprint writes its keys;
//  3. radix sort of the pixels with the labels as values (CUB, only the bits the band needs);
//  4. one thread per key: equal neighbouring pixels unite their labels in a lock-free union-find
//     (the larger root is hooked under the smaller with atomicCAS, so every root ends as the
//     smallest label of its component, exactly as on the CPU; path halving on reads);
//  5. roots, the columns and rows of the boxes' top-right pixels go back to the host, where
//     assemble_blocks (shared with the CPU) orders the blocks and picks the seeds.
// Rows are processed in bands of at most band_keys keys (plan_row_bands, shared with the CPU); the
// union-find on labels stays on the device across bands and merges components over band edges.
//
// Update seeds: one thread per pixel of the block's box runs inside_flat_shape (the CPU's code)
// on the flattened footprints and plans; flags come back and the host lists them row-major.
#include <groundplan/error.h>

#include <cuda_runtime.h>

#include <algorithm>
#include <bit>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <string>

#include "blocks/cuda_raster_backend.h"
#include "blocks/raster_common.h"

namespace groundplan::detail {
namespace {

void check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) throw GpuError(std::string("CUDA ") + what + ": " + cudaGetErrorString(e));
}

template <class T>
class DevBuf {
 public:
  DevBuf() = default;
  explicit DevBuf(std::size_t n) { resize(n); }
  DevBuf(const DevBuf&) = delete;
  DevBuf& operator=(const DevBuf&) = delete;
  ~DevBuf() {
    if (p_) cudaFree(p_);
  }
  void resize(std::size_t n) {
    if (n > cap_) {
      if (p_) cudaFree(p_);
      p_ = nullptr;
      cap_ = 0;
      check(cudaMalloc(&p_, std::max<std::size_t>(n, 1) * sizeof(T)), "cudaMalloc");
      cap_ = n;
    }
  }
  void upload(const T* src, std::size_t n) {
    resize(n);
    if (n) check(cudaMemcpy(p_, src, n * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy to device");
  }
  void download(T* dst, std::size_t n) const {
    if (n) check(cudaMemcpy(dst, p_, n * sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy to host");
  }
  T* get() const { return p_; }

 private:
  T* p_ = nullptr;
  std::size_t cap_ = 0;
};

constexpr int kThreads = 256;
unsigned grid_for(std::uint64_t n) { return static_cast<unsigned>((n + kThreads - 1) / kThreads); }

__global__ void ranges_kernel(const FootprintSet::Box* boxes, std::size_t n, PixelGrid g, std::int64_t* c0,
                              std::int64_t* c1, std::int64_t* r0, std::int64_t* r1) {
  const std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const FootprintSet::Box b = boxes[i];
  c0[i] = pixel_index(b.minx, g.origin_x, g.resolution_m, g.width);
  c1[i] = pixel_index(b.maxx, g.origin_x, g.resolution_m, g.width);
  r0[i] = pixel_index(b.miny, g.origin_y, g.resolution_m, g.height);
  r1[i] = pixel_index(b.maxy, g.origin_y, g.resolution_m, g.height);
}

__global__ void band_count_kernel(const std::int64_t* c0, const std::int64_t* c1, const std::int64_t* r0,
                                  const std::int64_t* r1, std::size_t n, std::int64_t row0, std::int64_t row1,
                                  unsigned long long* count) {
  const std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const std::int64_t ra = r0[i] > row0 ? r0[i] : row0, rb = r1[i] < row1 ? r1[i] : row1;
  count[i] = ra <= rb ? static_cast<unsigned long long>((rb - ra + 1) * (c1[i] - c0[i] + 1)) : 0ull;
}

__global__ void keys_kernel(const std::int64_t* c0, const std::int64_t* c1, const std::int64_t* r0,
                            const std::int64_t* r1, std::size_t n, std::int64_t row0, std::int64_t row1,
                            std::uint64_t width, const unsigned long long* offset, std::uint64_t* pixel,
                            std::uint32_t* label) {
  const std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const std::int64_t ra = r0[i] > row0 ? r0[i] : row0, rb = r1[i] < row1 ? r1[i] : row1;
  unsigned long long k = offset[i];
  for (std::int64_t r = ra; r <= rb; ++r)
    for (std::int64_t c = c0[i]; c <= c1[i]; ++c) {
      pixel[k] = static_cast<std::uint64_t>(r - row0) * width + static_cast<std::uint64_t>(c);
      label[k] = static_cast<std::uint32_t>(i);
      ++k;
    }
}

__device__ std::uint32_t find_root(std::uint32_t* parent, std::uint32_t x) {
  volatile std::uint32_t* p = parent;
  for (;;) {
    const std::uint32_t up = p[x];
    if (up == x) return x;
    const std::uint32_t upup = p[up];
    if (upup != up) p[x] = upup;  // path halving: upup is an ancestor of x as well
    x = upup;
  }
}

__device__ void unite(std::uint32_t* parent, std::uint32_t a, std::uint32_t b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  while (a != b) {
    if (a < b) {
      const std::uint32_t t = a;
      a = b;
      b = t;
    }
    // hook the larger root a under the smaller b, unless a stopped being a root meanwhile
    const std::uint32_t old = atomicCAS(parent + a, a, b);
    if (old == a) return;
    a = find_root(parent, old);
    b = find_root(parent, b);
  }
}

__global__ void iota_kernel(std::uint32_t* parent, std::size_t n) {
  const std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
  if (i < n) parent[i] = static_cast<std::uint32_t>(i);
}

__global__ void join_kernel(const std::uint64_t* pixel, const std::uint32_t* label, std::uint64_t m,
                            std::uint32_t* parent) {
  const std::uint64_t k = blockIdx.x * static_cast<std::uint64_t>(blockDim.x) + threadIdx.x + 1;
  if (k >= m) return;
  if (pixel[k] == pixel[k - 1]) unite(parent, label[k], label[k - 1]);
}

__global__ void roots_kernel(std::uint32_t* parent, std::size_t n, std::uint32_t* root) {
  const std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
  if (i < n) root[i] = find_root(parent, static_cast<std::uint32_t>(i));
}

__global__ void seeds_kernel(std::int64_t c0, std::int64_t r0, std::int64_t w, std::uint64_t npix, PixelGrid g,
                             std::uint32_t n_footprints, std::uint32_t n_shapes, const std::uint32_t* shape_first,
                             const std::uint32_t* poly_first, const std::uint32_t* ring_first, const double* xs,
                             const double* ys, std::uint8_t* flag) {
  const std::uint64_t idx = blockIdx.x * static_cast<std::uint64_t>(blockDim.x) + threadIdx.x;
  if (idx >= npix) return;
  const std::int64_t r = r0 + static_cast<std::int64_t>(idx / static_cast<std::uint64_t>(w));
  const std::int64_t c = c0 + static_cast<std::int64_t>(idx % static_cast<std::uint64_t>(w));
  const double x = g.origin_x + (static_cast<double>(c) + 0.5) * g.resolution_m;
  const double y = g.origin_y + (static_cast<double>(r) + 0.5) * g.resolution_m;
  bool covered = false, planned = false;
  for (std::uint32_t k = 0; k < n_footprints && !covered; ++k)
    covered = inside_flat_shape(shape_first, poly_first, ring_first, xs, ys, k, x, y);
  for (std::uint32_t k = n_footprints; k < n_shapes && !planned; ++k)
    planned = inside_flat_shape(shape_first, poly_first, ring_first, xs, ys, k, x, y);
  flag[idx] = covered != planned ? 1 : 0;
}

class CudaRasterBackend final : public RasterBackend {
 public:
  explicit CudaRasterBackend(std::uint64_t band_keys) : band_keys_(std::max<std::uint64_t>(band_keys, 1)) {
    check(cudaSetDevice(0), "cudaSetDevice");
    check(cudaFree(nullptr), "context creation");  // the context now, not inside the first timing
  }
  const char* name() const override { return "cuda"; }

  std::vector<Block> find_blocks(const FootprintSet& fps, const PixelGrid& grid, const Progress& progress) override {
    const std::size_t n = fps.indices.size();
    if (n == 0) return {};
    DevBuf<FootprintSet::Box> boxes;
    boxes.upload(fps.boxes.data(), n);
    DevBuf<std::int64_t> c0(n), c1(n), r0(n), r1(n);
    ranges_kernel<<<grid_for(n), kThreads>>>(boxes.get(), n, grid, c0.get(), c1.get(), r0.get(), r1.get());
    check(cudaGetLastError(), "ranges kernel");

    DevBuf<unsigned long long> count(n + 1), offset(n + 1);
    check(cudaMemset(count.get() + n, 0, sizeof(unsigned long long)), "cudaMemset");
    DevBuf<std::uint8_t> temp;
    auto scan = [&](std::int64_t row0, std::int64_t row1) {
      band_count_kernel<<<grid_for(n), kThreads>>>(c0.get(), c1.get(), r0.get(), r1.get(), n, row0, row1, count.get());
      check(cudaGetLastError(), "count kernel");
      std::size_t bytes = 0;
      check(cub::DeviceScan::ExclusiveSum(nullptr, bytes, count.get(), offset.get(), n + 1), "scan");
      temp.resize(bytes);
      check(cub::DeviceScan::ExclusiveSum(temp.get(), bytes, count.get(), offset.get(), n + 1), "scan");
      unsigned long long total = 0;
      check(cudaMemcpy(&total, offset.get() + n, sizeof total, cudaMemcpyDeviceToHost), "cudaMemcpy to host");
      return static_cast<std::uint64_t>(total);
    };

    std::vector<RowBand> bands{{0, grid.height - 1}};
    std::uint64_t first_total = scan(0, grid.height - 1);
    if (first_total > band_keys_) {
      PixelRanges pr;
      for (auto* v : {&pr.c0, &pr.c1, &pr.r0, &pr.r1}) v->resize(n);
      c0.download(pr.c0.data(), n);
      c1.download(pr.c1.data(), n);
      r0.download(pr.r0.data(), n);
      r1.download(pr.r1.data(), n);
      bands = plan_row_bands(pr, band_keys_);
    }

    DevBuf<std::uint32_t> parent(n);
    iota_kernel<<<grid_for(n), kThreads>>>(parent.get(), n);
    check(cudaGetLastError(), "iota kernel");
    DevBuf<std::uint64_t> pix_in, pix_out;
    DevBuf<std::uint32_t> lab_in, lab_out;
    const std::uint64_t width = static_cast<std::uint64_t>(grid.width);
    for (std::size_t bi = 0; bi < bands.size(); ++bi) {
      const RowBand band = bands[bi];
      const std::uint64_t total = bands.size() == 1 ? first_total : scan(band.row0, band.row1);
      if (total == 0) continue;
      pix_in.resize(total);
      pix_out.resize(total);
      lab_in.resize(total);
      lab_out.resize(total);
      keys_kernel<<<grid_for(n), kThreads>>>(c0.get(), c1.get(), r0.get(), r1.get(), n, band.row0, band.row1, width,
                                             offset.get(), pix_in.get(), lab_in.get());
      check(cudaGetLastError(), "keys kernel");
      const std::uint64_t cells = static_cast<std::uint64_t>(band.row1 - band.row0 + 1) * width;
      const int end_bit = std::max(1, static_cast<int>(std::bit_width(cells)));
      std::size_t bytes = 0;
      check(cub::DeviceRadixSort::SortPairs(nullptr, bytes, pix_in.get(), pix_out.get(), lab_in.get(), lab_out.get(),
                                            total, 0, end_bit),
            "radix sort");
      temp.resize(bytes);
      check(cub::DeviceRadixSort::SortPairs(temp.get(), bytes, pix_in.get(), pix_out.get(), lab_in.get(),
                                            lab_out.get(), total, 0, end_bit),
            "radix sort");
      if (total > 1) {
        join_kernel<<<grid_for(total - 1), kThreads>>>(pix_out.get(), lab_out.get(), total, parent.get());
        check(cudaGetLastError(), "join kernel");
      }
      check(cudaDeviceSynchronize(), "blocks");
      progress.report(0.9 * static_cast<double>(bi + 1) / static_cast<double>(bands.size()), "joined pixels");
    }
    DevBuf<std::uint32_t> root_d(n);
    roots_kernel<<<grid_for(n), kThreads>>>(parent.get(), n, root_d.get());
    check(cudaGetLastError(), "roots kernel");
    std::vector<std::uint32_t> root(n);
    std::vector<std::int64_t> hc1(n), hr1(n);
    root_d.download(root.data(), n);
    c1.download(hc1.data(), n);
    r1.download(hr1.data(), n);
    return assemble_blocks(fps, root, hc1.data(), hr1.data());
  }

  Seeds find_new_seeds(const FootprintSet& fps, const Block& block, const std::vector<GroundPlan>& so_far,
                       const PixelGrid& grid) override {
    Seeds s;
    const SeedProblem sp = make_seed_problem(fps, block, so_far, grid);
    if (sp.c1 < sp.c0 || sp.r1 < sp.r0) return s;
    const std::int64_t w = sp.c1 - sp.c0 + 1;
    const std::uint64_t npix = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(sp.r1 - sp.r0 + 1);
    const FlatShapes& f = sp.shapes;
    DevBuf<std::uint32_t> shape_first, poly_first, ring_first;
    DevBuf<double> xs, ys;
    shape_first.upload(f.shape_first.data(), f.shape_first.size());
    poly_first.upload(f.poly_first.data(), f.poly_first.size());
    ring_first.upload(f.ring_first.data(), f.ring_first.size());
    xs.upload(f.xs.data(), f.xs.size());
    ys.upload(f.ys.data(), f.ys.size());
    DevBuf<std::uint8_t> flag(npix);
    seeds_kernel<<<grid_for(npix), kThreads>>>(sp.c0, sp.r0, w, npix, grid, sp.n_footprints, f.size(),
                                               shape_first.get(), poly_first.get(), ring_first.get(), xs.get(),
                                               ys.get(), flag.get());
    check(cudaGetLastError(), "seeds kernel");
    std::vector<std::uint8_t> h(npix);
    flag.download(h.data(), npix);
    for (std::uint64_t idx = 0; idx < npix; ++idx)
      if (h[idx])
        s.pixels.push_back({sp.c0 + static_cast<std::int64_t>(idx % static_cast<std::uint64_t>(w)),
                            sp.r0 + static_cast<std::int64_t>(idx / static_cast<std::uint64_t>(w))});
    return s;
  }

 private:
  std::uint64_t band_keys_;
};

int device_count() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    cudaGetLastError();  // clear it: no device or no driver is an answer, not an error
    return 0;
  }
  return count;
}

RasterBackend* make_backend(std::uint64_t band_keys, char* error, std::size_t error_size) {
  int count = 0;
  const cudaError_t e = cudaGetDeviceCount(&count);
  if (e != cudaSuccess || count <= 0) {
    // without libcuda (no NVIDIA driver) the static runtime says "driver version is insufficient": say both
    const std::string why =
        e == cudaErrorInsufficientDriver
            ? std::string("no CUDA device answers: no NVIDIA driver, or one older than this CUDA runtime (cudaGetDeviceCount: ") +
                  cudaGetErrorString(e) + ")"
            : std::string("no CUDA device answers (cudaGetDeviceCount: ") +
                  (e != cudaSuccess ? cudaGetErrorString(e) : "no device") + ")";
    cudaGetLastError();
    if (error_size) {
      const std::size_t n = std::min(why.size(), error_size - 1);
      why.copy(error, n);
      error[n] = '\0';
    }
    return nullptr;
  }
  return new CudaRasterBackend(band_keys);
}

constexpr CudaModuleApi kApi{GROUNDPLAN_CUDA_MODULE_BUILD, &device_count, &make_backend};

}  // namespace
}  // namespace groundplan::detail

// The module's one exported symbol (every other one is hidden: gpu/CMakeLists.txt).
extern "C" __attribute__((visibility("default"))) const groundplan::detail::CudaModuleApi* groundplan_cuda_module_api() {
  return &groundplan::detail::kApi;
}

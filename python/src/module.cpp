// SPDX-License-Identifier: MIT
// groundplan._groundplan: the union engine and the pipeline for Python (issue 23). The pure-Python package
// python/groundplan/ wraps these functions (Shapely/GeoPandas conversion, type hints, docstrings).
//
// Geometries cross the boundary as WKB: one list of bytes in, one list of bytes out, parsed and written
// here (no Python call per vertex). The work runs on a thread of its own with the GIL released; the
// calling thread wakes every few milliseconds to run Python's signal handlers (Ctrl-C) and the progress
// callback, so both always run on the thread that called, and a KeyboardInterrupt or an exception in the
// callback cancels the engine through Progress (it throws Cancelled at its next report).
#include "ogr_groundplan.h"
#include "open_options.h"

#include <groundplan/error.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/gis/pipeline.h>
#include <groundplan/ground_plans.h>
#include <groundplan/level_of_detail.h>
#include <groundplan/progress.h>
#include <groundplan/types.h>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cpl_string.h>
#include <geos_c.h>
#include <gdal.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <dlfcn.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <exception>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace py = pybind11;
using namespace groundplan;

namespace {

/// A geometry that is not polygonal: TypeError (std::invalid_argument would be pybind11's ValueError).
struct NotPolygonal : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// CPU seconds of the whole process, all threads (the stages of union() run one after the other, so the
/// difference around a stage is that stage's CPU time, whatever the number of threads it used).
double process_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Asks Linux for transparent huge pages behind a large buffer we own and have not touched yet: its first
/// touch then costs one page fault per 2 MiB instead of one per 4 KiB. The vector of 60k footprints is 8 MB
/// of fresh memory on every call (glibc maps and unmaps it); on the VM of tests/bench/RESULTS.md a page
/// fault costs ~50 us and these faults were 0.11 s of a 0.5 s call, the largest part of the conversion.
/// Only advice: where THP is off, or the range holds no whole huge page, nothing changes.
void advise_huge_pages(void* data, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t huge = 2u << 20;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + huge - 1) & ~(huge - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(huge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// Minor page faults of the process so far (first touches of fresh memory: what makes a first call slower).
long minor_faults() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_minflt;
}

// ---------------------------------------------------------------------------------------------------------
// WKB in: Polygon, MultiPolygon, or a GeometryCollection of those; ISO (1003, 2003, 3003) and extended
// (0x80000000 Z, 0x40000000 M, 0x20000000 SRID) flags; either byte order. Z and M are dropped.

struct WkbError {
  std::string what;
  bool type_error;  // a geometry that is not polygonal (TypeError) rather than malformed bytes (ValueError)
};

class WkbReader {
 public:
  WkbReader(const char* data, std::size_t size) : p_(reinterpret_cast<const unsigned char*>(data)), end_(p_ + size) {}

  void read_footprint(std::vector<Polygon>& out) {
    geometry(out, 0);
    if (p_ != end_) throw WkbError{std::to_string(end_ - p_) + " bytes after the end of the geometry", false};
  }

 private:
  void need(std::size_t n) const {
    if (static_cast<std::size_t>(end_ - p_) < n) throw WkbError{"truncated WKB", false};
  }
  std::uint32_t u32(bool le) {
    need(4);
    std::uint32_t v = le ? (p_[0] | p_[1] << 8 | p_[2] << 16 | std::uint32_t(p_[3]) << 24)
                         : (p_[3] | p_[2] << 8 | p_[1] << 16 | std::uint32_t(p_[0]) << 24);
    p_ += 4;
    return v;
  }
  double f64(bool le) {
    unsigned char b[8];
    for (int i = 0; i < 8; ++i) b[i] = le ? p_[i] : p_[7 - i];
    p_ += 8;
    double v;
    std::memcpy(&v, b, 8);
    return v;
  }
  void geometry(std::vector<Polygon>& out, int depth) {
    if (depth > 32) throw WkbError{"WKB nested too deep", false};
    need(5);
    const unsigned char order = *p_++;
    if (order > 1) throw WkbError{"bad WKB byte order " + std::to_string(order), false};
    const bool le = order == 1;
    const std::uint32_t raw = u32(le);
    bool z = raw & 0x80000000u, m = raw & 0x40000000u;
    if (raw & 0x20000000u) u32(le);  // EWKB SRID
    std::uint32_t type = raw & 0x0FFFFFFFu;
    if (type >= 1000 && type < 4000) {
      z = z || type / 1000 == 1 || type / 1000 == 3;
      m = m || type / 1000 == 2 || type / 1000 == 3;
      type %= 1000;
    }
    const std::size_t dims = 2 + z + m;
    switch (type) {
      case 3: polygon(out, le, dims); break;
      case 6:
      case 7: {
        const std::uint32_t n = u32(le);
        need(std::size_t(n) * 5 > std::size_t(end_ - p_) ? std::size_t(n) * 5 : 0);
        for (std::uint32_t i = 0; i < n; ++i) geometry(out, depth + 1);
        break;
      }
      default: {
        static const char* names[] = {"Geometry", "Point", "LineString", "Polygon", "MultiPoint", "MultiLineString"};
        throw WkbError{std::string("a ") + (type < 6 ? names[type] : ("WKB type " + std::to_string(type)).c_str()) +
                           " is not a polygon or multipolygon",
                       true};
      }
    }
  }
  void polygon(std::vector<Polygon>& out, bool le, std::size_t dims) {
    const std::uint32_t rings = u32(le);
    if (rings == 0) return;  // POLYGON EMPTY
    need(std::size_t(rings) * 4);
    Polygon poly;
    for (std::uint32_t r = 0; r < rings; ++r) {
      const std::uint32_t n = u32(le);
      need(std::size_t(n) * dims * 8);
      Ring ring(n);
      for (std::uint32_t i = 0; i < n; ++i) {
        ring[i].x = f64(le);
        ring[i].y = f64(le);
        p_ += 8 * (dims - 2);
      }
      if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();  // the closing point
      if (r == 0)
        poly.outer = std::move(ring);
      else
        poly.holes.push_back(std::move(ring));
    }
    out.push_back(std::move(poly));
  }

  const unsigned char* p_;
  const unsigned char* end_;
};

// WKB out: little-endian 2D Polygon, rings closed.
std::string polygon_wkb(const Polygon& poly) {
  std::size_t rings = poly.outer.empty() ? 0 : 1 + poly.holes.size();
  std::size_t size = 9;
  auto ring_size = [](const Ring& r) { return 4 + (r.size() + 1) * 16; };
  if (rings) {
    size += ring_size(poly.outer);
    for (const Ring& h : poly.holes) size += ring_size(h);
  }
  std::string out(size, '\0');
  char* p = out.data();
  auto put32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) *p++ = static_cast<char>((v >> (8 * i)) & 0xff);
  };
  auto putd = [&](double d) {
    std::memcpy(p, &d, 8);  // x86-64 and aarch64 are little-endian
    p += 8;
  };
  *p++ = 1;
  put32(3);
  put32(static_cast<std::uint32_t>(rings));
  auto ring = [&](const Ring& r) {
    put32(static_cast<std::uint32_t>(r.size() + 1));
    for (std::size_t i = 0; i <= r.size(); ++i) {
      putd(r[i % r.size()].x);
      putd(r[i % r.size()].y);
    }
  };
  if (rings) {
    ring(poly.outer);
    for (const Ring& h : poly.holes) ring(h);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// GEOS geometries in (Shapely 1.8's fast path): Shapely hands the addresses of its GEOS geometries, read
// here with the GEOS C API. Only used when Shapely's libgeos_c is the very library this module links (the
// wrapper compares the addresses of GEOSversion), and the Python list of geometries keeps them alive.

/// One GEOS context per thread (the reentrant API's handles are not to be shared between threads).
GEOSContextHandle_t geos_handle() {
  thread_local struct Handle {
    GEOSContextHandle_t h = GEOS_init_r();
    ~Handle() { GEOS_finish_r(h); }
  } handle;
  return handle.h;
}

#if GEOS_VERSION_MAJOR > 3 || (GEOS_VERSION_MAJOR == 3 && GEOS_VERSION_MINOR >= 10)
#define GROUNDPLAN_GEOS_BUFFERS 1  // GEOSCoordSeq_copyToBuffer_r / copyFromBuffer_r: one call per ring
static_assert(sizeof(Point2) == 2 * sizeof(double), "a Ring is an array of x, y doubles");
#endif

void geos_ring(GEOSContextHandle_t h, const GEOSGeometry* ring, Ring& out) {
  const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(h, ring);
  unsigned int n = 0;
  if (!seq || !GEOSCoordSeq_getSize_r(h, seq, &n)) throw WkbError{"unreadable GEOS ring", false};
  out.resize(n);
#ifdef GROUNDPLAN_GEOS_BUFFERS
  if (n && !GEOSCoordSeq_copyToBuffer_r(h, seq, &out[0].x, 0, 0)) throw WkbError{"unreadable GEOS ring", false};
#else
  for (unsigned int i = 0; i < n; ++i) GEOSCoordSeq_getXY_r(h, seq, i, &out[i].x, &out[i].y);
#endif
  if (out.size() > 1 && out.front() == out.back()) out.pop_back();
}

void geos_geometry(GEOSContextHandle_t h, const GEOSGeometry* g, std::vector<Polygon>& out, int depth) {
  if (depth > 32) throw WkbError{"geometry nested too deep", false};
  const int type = GEOSGeomTypeId_r(h, g);
  if (type == GEOS_POLYGON) {
    if (GEOSisEmpty_r(h, g) == 1) return;
    Polygon poly;
    geos_ring(h, GEOSGetExteriorRing_r(h, g), poly.outer);
    const int holes = GEOSGetNumInteriorRings_r(h, g);
    poly.holes.resize(holes > 0 ? holes : 0);
    for (int k = 0; k < holes; ++k) geos_ring(h, GEOSGetInteriorRingN_r(h, g, k), poly.holes[k]);
    out.push_back(std::move(poly));
  } else if (type == GEOS_MULTIPOLYGON || type == GEOS_GEOMETRYCOLLECTION) {
    const int n = GEOSGetNumGeometries_r(h, g);
    for (int k = 0; k < n; ++k) geos_geometry(h, GEOSGetGeometryN_r(h, g, k), out, depth + 1);
  } else {
    static const char* names[] = {"Point", "LineString", "LinearRing", "Polygon", "MultiPoint", "MultiLineString"};
    throw WkbError{std::string("a ") + (type >= 0 && type < 6 ? names[type] : "geometry of GEOS type " + std::to_string(type)) +
                       " is not a polygon or multipolygon",
                   true};
  }
}

// GEOS geometries out (Shapely 1.8's fast path, the same condition as the way in): the plans made as GEOS
// polygons here, in parallel, and handed to Python as addresses; Shapely's Polygon objects then own them
// (groundplan/__init__.py). Until that hand-over they belong to a GeosPlans, which destroys what is left.

class GeosPlans {
 public:
  GeosPlans() = default;
  GeosPlans(GeosPlans&& o) noexcept : g_(std::move(o.g_)) { o.g_.clear(); }
  GeosPlans& operator=(GeosPlans&&) = delete;
  ~GeosPlans() {
    for (GEOSGeometry* g : g_)
      if (g) GEOSGeom_destroy_r(geos_handle(), g);
  }
  void resize(std::size_t n) { g_.assign(n, nullptr); }
  std::size_t size() const { return g_.size(); }
  GEOSGeometry*& operator[](std::size_t i) { return g_[i]; }
  /// Gives up geometry i: the caller owns it now.
  std::uintptr_t release(std::size_t i) { return reinterpret_cast<std::uintptr_t>(std::exchange(g_[i], nullptr)); }

 private:
  std::vector<GEOSGeometry*> g_;
};

/// A ring of a plan as a closed GEOS LinearRing (nullptr where GEOS refuses it).
GEOSGeometry* geos_linear_ring(GEOSContextHandle_t h, const Ring& r, std::vector<double>& buf) {
  const std::size_t n = r.size() + 1;
  GEOSCoordSequence* seq = nullptr;
#ifdef GROUNDPLAN_GEOS_BUFFERS
  buf.resize(2 * n);
  if (!r.empty()) std::memcpy(buf.data(), r.data(), r.size() * sizeof(Point2));
  buf[2 * n - 2] = r.empty() ? 0 : r[0].x;
  buf[2 * n - 1] = r.empty() ? 0 : r[0].y;
  seq = GEOSCoordSeq_copyFromBuffer_r(h, buf.data(), static_cast<unsigned int>(n), 0, 0);
#else
  (void)buf;
  seq = GEOSCoordSeq_create_r(h, static_cast<unsigned int>(n), 2);
  for (std::size_t i = 0; seq && i < n; ++i) GEOSCoordSeq_setXY_r(h, seq, static_cast<unsigned int>(i), r[i % r.size()].x, r[i % r.size()].y);
#endif
  return seq ? GEOSGeom_createLinearRing_r(h, seq) : nullptr;  // takes the sequence
}

/// A plan as a GEOS Polygon with the coordinates polygon_wkb writes (rings closed by their first point).
GEOSGeometry* geos_polygon(GEOSContextHandle_t h, const Polygon& poly) {
  if (poly.outer.empty()) return GEOSGeom_createEmptyPolygon_r(h);
  thread_local std::vector<double> buf;
  GEOSGeometry* shell = geos_linear_ring(h, poly.outer, buf);
  if (!shell) return nullptr;
  std::vector<GEOSGeometry*> holes(poly.holes.size(), nullptr);
  bool ok = true;
  for (std::size_t k = 0; k < holes.size() && ok; ++k) ok = (holes[k] = geos_linear_ring(h, poly.holes[k], buf)) != nullptr;
  if (!ok) {
    GEOSGeom_destroy_r(h, shell);
    for (GEOSGeometry* g : holes)
      if (g) GEOSGeom_destroy_r(h, g);
    return nullptr;
  }
  return GEOSGeom_createPolygon_r(h, shell, holes.data(), static_cast<unsigned int>(holes.size()));  // takes the rings
}

/// Shapely 2 objects owning the GEOS polygons at `addresses`, made by Shapely's own C API (the capsule
/// "shapely.lib._C_API" of shapely/src/c_api.h; entry 0: PyObject* CreateGeometry(GEOSGeometry*, context)).
/// Only for a Shapely whose libgeos_c is this module's (the wrapper checks). On failure the geometries not
/// yet taken over are freed. GIL held.
py::list shapely2_geometries(const std::vector<std::uintptr_t>& addresses) {
  std::size_t i = 0;
  auto free_rest = [&] {
    for (std::size_t k = i; k < addresses.size(); ++k)
      if (addresses[k]) GEOSGeom_destroy_r(geos_handle(), reinterpret_cast<GEOSGeometry*>(addresses[k]));
  };
  void** api = static_cast<void**>(PyCapsule_Import("shapely.lib._C_API", 0));
  if (!api) {
    free_rest();
    throw py::error_already_set();
  }
  using Create = PyObject* (*)(GEOSGeometry*, GEOSContextHandle_t);
  const auto create = reinterpret_cast<Create>(api[0]);
  py::list out(addresses.size());
  for (; i < addresses.size(); ++i) {
    PyObject* o = create(reinterpret_cast<GEOSGeometry*>(addresses[i]), geos_handle());
    if (!o) {  // Shapely did not take this one over
      free_rest();
      throw py::error_already_set();
    }
    PyList_SET_ITEM(out.ptr(), static_cast<Py_ssize_t>(i), o);  // steals the reference
  }
  return out;
}

/// The address of GEOSversion as the shared object `path` (already loaded) binds it: the libgeos_c that
/// Shapely 2's extension uses, to compare with this module's.
std::uintptr_t geos_version_address_in(const std::string& path) {
  void* h = dlopen(path.c_str(), RTLD_LAZY | RTLD_NOLOAD);
  if (!h) return 0;
  void* sym = dlsym(h, "GEOSversion");
  dlclose(h);
  return reinterpret_cast<std::uintptr_t>(sym);
}

// ---------------------------------------------------------------------------------------------------------
// Running engine work off the Python thread, with Ctrl-C and a progress callback.

struct Shared {
  std::mutex mutex;
  std::condition_variable cv;
  bool done = false;
  double fraction = -1;      // the newest reported fraction not yet passed to Python
  std::string message;
  bool pending = false;
  std::atomic<bool> cancel{false};
};

/// Runs work(progress) on a thread of its own with the GIL released. Returns its result; re-raises what
/// it threw (translated by the exception translators below), or the Python exception that cancelled it
/// (KeyboardInterrupt from Ctrl-C, whatever `callback` raised). `callback(fraction, message)` returning
/// False cancels with groundplan.Cancelled. Must be called with the GIL held.
template <class Result, class Work>
Result run_cancellable(Work&& work, const py::object& callback) {
  Shared s;
  Progress progress([&s](double fraction, const char* message) {
    if (s.cancel.load(std::memory_order_relaxed)) return false;
    std::lock_guard<std::mutex> lock(s.mutex);
    if (fraction > s.fraction) {
      s.fraction = fraction;
      s.message = message ? message : "";
      s.pending = true;
    }
    return true;
  });
  std::optional<Result> result;
  std::exception_ptr error;
  std::optional<py::error_already_set> py_error;
  double last_sent = -1;
  bool refused = false;  // the callback returned False
  auto forward = [&] {  // GIL held
    if (callback.is_none() || py_error || refused) return;  // never called again once it said stop
    double f;
    std::string msg;
    {
      std::lock_guard<std::mutex> lock(s.mutex);
      if (!s.pending) return;
      s.pending = false;
      f = s.fraction;
      msg = s.message;
    }
    if (f <= last_sent) return;
    last_sent = f;
    try {
      py::object r = callback(f, msg);
      if (r.ptr() == Py_False) {  // exactly False: None (no return) goes on
        refused = true;
        s.cancel = true;
      }
    } catch (py::error_already_set& e) {
      py_error = std::move(e);
      s.cancel = true;
    }
  };

  std::thread worker;
  {
    py::gil_scoped_release release;
    worker = std::thread([&] {
      try {
        result.emplace(work(progress));
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(s.mutex);
      s.done = true;
      s.cv.notify_all();
    });
  }
  auto join = [&] {
    py::gil_scoped_release release;
    worker.join();
  };
  try {
    for (;;) {
      bool done;
      {
        py::gil_scoped_release release;
        std::unique_lock<std::mutex> lock(s.mutex);
        s.cv.wait_for(lock, std::chrono::milliseconds(20), [&] { return s.done; });
        done = s.done;
      }
      if (!py_error && PyErr_CheckSignals() != 0) {  // Ctrl-C: KeyboardInterrupt is now set
        py_error.emplace();
        s.cancel = true;
      }
      forward();
      if (done) break;
    }
  } catch (...) {  // never leave with the worker running (std::thread's destructor would terminate)
    s.cancel = true;
    join();
    throw;
  }
  join();
  if (py_error) throw *py_error;
  if (error) std::rethrow_exception(error);
  forward();  // the last report (1.0) when it came after the last wake-up
  if (py_error) throw *py_error;
  if (refused) throw Cancelled();  // even when the work had finished: the caller said stop
  return std::move(*result);
}

py::dict problem_dict(const Problem& p, bool with_index) {
  py::dict d;
  if (with_index) {
    // union(): the source id is the input's position
    py::object index = py::none();
    if (!p.source_id.empty() && p.source_id.find_first_not_of("0123456789") == std::string::npos)
      index = py::int_(std::stoll(p.source_id));
    d["index"] = index;
  } else {
    d["source_id"] = p.source_id;
    d["file"] = p.file;
  }
  d["stage"] = p.stage;
  d["code"] = p.code;
  d["reason"] = p.reason;
  return d;
}

// ---------------------------------------------------------------------------------------------------------

using ReadOne = std::function<void(std::size_t, std::vector<Polygon>&)>;  // throws WkbError

/// The union of n inputs read by read_one; the plans as WKB bytes, or (geos_out) as the addresses of GEOS
/// polygons that the caller must own (groundplan/__init__.py wraps them in Shapely objects at once).
py::dict union_inputs(std::size_t n, const ReadOne& read_one, bool geos_out, int threads, double resolution,
                      const std::string& device, double snap, double close_gaps, double simplify, double min_hole_area,
                      double min_area, const py::object& progress) {
  if (threads < 0) throw InvalidArgument("threads: " + std::to_string(threads) + " is not >= 1 (0 = all cores)");
  for (double v : {resolution, snap, close_gaps, simplify, min_hole_area, min_area})
    if (!(v >= 0) || !std::isfinite(v))
      throw InvalidArgument("resolution, snap, close_gaps, simplify, min_hole_area and min_area must be finite and >= 0");
  UnionParams up;
  up.resolution_m = resolution;
  up.device = gis::device_from_string(device);
  up.threads = threads;
  LodParams lod;
  lod.snap_m = snap;
  lod.close_gaps_m = close_gaps;
  lod.simplify_m = simplify;
  lod.min_hole_area_m2 = min_hole_area;
  lod.min_area_m2 = min_area;

  struct Out {
    std::vector<GroundPlan> plans;
    std::vector<Problem> problems;
    std::vector<std::string> plan_wkb;
    GeosPlans plan_geos;
    double parse_s = 0, union_s = 0, write_s = 0;
    double parse_cpu_s = 0, union_cpu_s = 0, write_cpu_s = 0, alloc_s = 0;
    long parse_faults = 0, union_faults = 0;
  };
  Out out = run_cancellable<Out>(
      [&](const Progress& prog) {
        Out o;
        const int arena_threads = static_cast<int>(gis::thread_count(threads));
        tbb::task_arena arena(arena_threads);
        arena.execute([&] {
          auto t0 = std::chrono::steady_clock::now();
          double c0 = process_cpu_s();
          long f0 = minor_faults();
          std::vector<Footprint> fps;
          fps.reserve(n);
          advise_huge_pages(fps.data(), n * sizeof(Footprint));
          fps.resize(n);
          o.alloc_s = seconds_since(t0);
          std::vector<std::optional<WkbError>> errors(n);
          tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
              fps[i].source_id = std::to_string(i);
              try {
                read_one(i, fps[i].polygons);
              } catch (const WkbError& e) {
                errors[i] = e;
              }
            }
          });
          for (std::size_t i = 0; i < n; ++i)
            if (errors[i]) {
              const std::string what = "geometry " + std::to_string(i) + ": " + errors[i]->what;
              if (errors[i]->type_error) throw NotPolygonal(what);
              throw InvalidArgument(what);
            }
          o.parse_s = seconds_since(t0);
          o.parse_cpu_s = process_cpu_s() - c0;
          o.parse_faults = minor_faults() - f0;
          f0 = minor_faults();
          t0 = std::chrono::steady_clock::now();
          c0 = process_cpu_s();
          o.plans = build_ground_plans(fps, up, lod, o.problems, prog);
          o.union_s = seconds_since(t0);
          o.union_cpu_s = process_cpu_s() - c0;
          o.union_faults = minor_faults() - f0;
          t0 = std::chrono::steady_clock::now();
          c0 = process_cpu_s();
          if (geos_out) {
            o.plan_geos.resize(o.plans.size());
            std::atomic<std::size_t> failed{o.plans.size()};
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, o.plans.size(), 64),
                              [&](const tbb::blocked_range<std::size_t>& r) {
                                const GEOSContextHandle_t h = geos_handle();
                                for (std::size_t i = r.begin(); i != r.end(); ++i)
                                  if (!(o.plan_geos[i] = geos_polygon(h, o.plans[i].polygon))) failed = i;
                              });
            if (failed != o.plans.size())
              throw Error("GEOS refused plan " + std::to_string(failed.load()) + " as a polygon");
          } else {
            o.plan_wkb.resize(o.plans.size());
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, o.plans.size(), 64),
                              [&](const tbb::blocked_range<std::size_t>& r) {
                                for (std::size_t i = r.begin(); i != r.end(); ++i) o.plan_wkb[i] = polygon_wkb(o.plans[i].polygon);
                              });
          }
          o.write_s = seconds_since(t0);
          o.write_cpu_s = process_cpu_s() - c0;
        });
        return o;
      },
      progress);

  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = process_cpu_s();
  py::list plans(out.plans.size()), members(out.plans.size()), areas(out.plans.size());
  for (std::size_t i = 0; i < out.plans.size(); ++i) {
    plans[i] = geos_out ? py::object(py::int_(out.plan_geos.release(i))) : py::object(py::bytes(out.plan_wkb[i]));
    const auto& m = out.plans[i].members;
    py::list ml(m.size());
    for (std::size_t k = 0; k < m.size(); ++k) ml[k] = py::int_(m[k]);
    members[i] = std::move(ml);
    areas[i] = py::float_(out.plans[i].area_m2);
  }
  py::list problems;
  for (const Problem& p : out.problems) problems.append(problem_dict(p, true));
  py::dict timings;
  timings["parse_s"] = out.parse_s;
  timings["union_s"] = out.union_s;
  timings["write_s"] = out.write_s;
  timings["to_python_s"] = seconds_since(t0);
  timings["parse_cpu_s"] = out.parse_cpu_s;
  timings["union_cpu_s"] = out.union_cpu_s;
  timings["write_cpu_s"] = out.write_cpu_s;
  timings["to_python_cpu_s"] = process_cpu_s() - c0;
  timings["parse_alloc_s"] = out.alloc_s;  // of parse_s: the vector of footprints
  timings["parse_minor_faults"] = out.parse_faults;
  timings["union_minor_faults"] = out.union_faults;
  py::dict r;
  r["plans"] = plans;
  r["members"] = members;
  r["areas"] = areas;
  r["problems"] = problems;
  r["timings"] = timings;
  return r;
}

#define GROUNDPLAN_UNION_PARAMS                                                                                \
  bool geos_out, int threads, double resolution, const std::string &device, double snap, double close_gaps, double simplify, \
      double min_hole_area, double min_area, const py::object &progress
#define GROUNDPLAN_UNION_ARGS geos_out, threads, resolution, device, snap, close_gaps, simplify, min_hole_area, min_area, progress

py::dict union_wkb(const py::list& wkbs, GROUNDPLAN_UNION_PARAMS) {
  // The bytes objects stay alive in `wkbs` (held by the caller) while the worker reads them.
  const std::size_t n = py::len(wkbs);
  std::vector<std::pair<const char*, std::size_t>> views(n);
  for (std::size_t i = 0; i < n; ++i) {
    PyObject* o = PyList_GET_ITEM(wkbs.ptr(), static_cast<Py_ssize_t>(i));
    char* data = nullptr;
    Py_ssize_t size = 0;
    if (!PyBytes_Check(o) || PyBytes_AsStringAndSize(o, &data, &size) != 0)
      throw py::type_error("geometry " + std::to_string(i) + ": expected WKB bytes, got " +
                           std::string(py::str(py::type::handle_of(o).attr("__name__"))));
    views[i] = {data, static_cast<std::size_t>(size)};
  }
  return union_inputs(
      n, [&](std::size_t i, std::vector<Polygon>& out) { WkbReader(views[i].first, views[i].second).read_footprint(out); },
      GROUNDPLAN_UNION_ARGS);
}

py::dict union_geos(const std::vector<std::uintptr_t>& addresses, GROUNDPLAN_UNION_PARAMS) {
  return union_inputs(
      addresses.size(),
      [&](std::size_t i, std::vector<Polygon>& out) {
        geos_geometry(geos_handle(), reinterpret_cast<const GEOSGeometry*>(addresses[i]), out, 0);
      },
      GROUNDPLAN_UNION_ARGS);
}

// ---------------------------------------------------------------------------------------------------------

/// One layer of the driver's dataset as columns: {"columns": {name: [values]}, "geometry": [WKB] or None}.
py::dict layer_columns(OGRLayer* layer) {
  OGRFeatureDefn* defn = layer->GetLayerDefn();
  const int nf = defn->GetFieldCount();
  std::vector<py::list> cols(nf);
  const bool has_geom = defn->GetGeomType() != wkbNone;
  py::list geoms;
  std::vector<unsigned char> buf;
  layer->ResetReading();
  for (;;) {
    std::unique_ptr<OGRFeature> f(layer->GetNextFeature());
    if (!f) break;
    for (int k = 0; k < nf; ++k) {
      if (!f->IsFieldSetAndNotNull(k)) {
        cols[k].append(py::none());
        continue;
      }
      switch (defn->GetFieldDefn(k)->GetType()) {
        case OFTInteger: cols[k].append(py::int_(f->GetFieldAsInteger(k))); break;
        case OFTInteger64: cols[k].append(py::int_(static_cast<long long>(f->GetFieldAsInteger64(k)))); break;
        case OFTReal: cols[k].append(py::float_(f->GetFieldAsDouble(k))); break;
        default: cols[k].append(py::str(f->GetFieldAsString(k))); break;
      }
    }
    if (has_geom) {
      const OGRGeometry* g = f->GetGeometryRef();
      if (!g) {
        geoms.append(py::none());
      } else {
        buf.resize(g->WkbSize());
        g->exportToWkb(wkbNDR, buf.data(), wkbVariantIso);
        geoms.append(py::bytes(reinterpret_cast<const char*>(buf.data()), buf.size()));
      }
    }
  }
  py::dict columns;
  for (int k = 0; k < nf; ++k) columns[py::str(defn->GetFieldDefn(k)->GetNameRef())] = cols[k];
  py::dict d;
  d["columns"] = columns;
  d["geometry"] = has_geom ? py::object(geoms) : py::object(py::none());
  return d;
}

py::dict read_inputs(const std::vector<std::string>& inputs, const std::map<std::string, std::string>& options,
              const py::object& progress) {
  if (inputs.empty()) throw InvalidArgument("read: names no input file");
  CPLStringList oo;
  for (const auto& [k, v] : options) oo.SetNameValue(k.c_str(), v.c_str());
  // The driver's open options (the CLI's flags map onto the same ones): one place reads the settings.
  gis::PipelineOptions o = driver::pipeline_options_from(std::string(driver::kPrefix) + inputs.front(), oo.List());
  o.inputs = inputs;  // as given: a path may hold a comma
  if (GDALGetDriverCount() == 0) GDALAllRegister();  // OGR inputs (issue 22), as the CLI does

  auto result = std::make_shared<gis::PipelineResult>(
      run_cancellable<gis::PipelineResult>([&](const Progress& prog) { return gis::run_pipeline(o, prog); }, progress));

  driver::OGRGroundPlanDataSource ds("GROUNDPLAN:" + inputs.front(), result, 0, o.threads);
  py::dict layers;
  for (const char* name : {"ground_plans", "footprints", "problems"}) layers[name] = layer_columns(ds.GetLayerByName(name));
  py::dict r;
  r["layers"] = layers;
  r["crs_wkt"] = result->crs_wkt;
  r["crs_name"] = result->crs_name;
  py::dict stats;
  stats["buildings_read"] = result->buildings_read;
  stats["buildings_dropped"] = result->buildings_dropped;
  stats["blocks"] = result->blocks;
  stats["raster_backend"] = result->raster_backend;
  stats["read_s"] = result->timings.read_s;
  stats["footprints_s"] = result->timings.footprints_s;
  stats["blocks_s"] = result->timings.blocks_s;
  stats["union_s"] = result->timings.union_s;
  stats["lod_s"] = result->timings.lod_s;
  r["stats"] = stats;
  return r;
}

}  // namespace

/// Bytes of a Python bytes object (kept alive by the caller's list).
std::pair<const char*, std::size_t> bytes_view(PyObject* o, const std::string& what) {
  char* data = nullptr;
  Py_ssize_t size = 0;
  if (!PyBytes_Check(o) || PyBytes_AsStringAndSize(o, &data, &size) != 0)
    throw py::type_error(what + ": expected WKB bytes, got " + std::string(py::str(py::type::handle_of(o).attr("__name__"))));
  return {data, static_cast<std::size_t>(size)};
}

/// `groundplan --verify` for Python: footprints and plans as WKB, plan members as input positions, ids to name
/// the buildings by; the comparison with GEOS's union of the footprints, every difference decided exactly.
py::dict verify_wkb(const py::list& footprints, const py::list& plans, const std::vector<std::vector<std::uint32_t>>& members,
                    const std::vector<std::string>& ids) {
  std::vector<Footprint> fps(py::len(footprints));
  for (std::size_t i = 0; i < fps.size(); ++i) {
    const std::string what = "geometry " + std::to_string(i);
    const auto v = bytes_view(PyList_GET_ITEM(footprints.ptr(), static_cast<Py_ssize_t>(i)), what);
    fps[i].source_id = i < ids.size() ? ids[i] : std::to_string(i);
    try {
      WkbReader(v.first, v.second).read_footprint(fps[i].polygons);
    } catch (const WkbError& e) {
      if (e.type_error) throw NotPolygonal(what + ": " + e.what);
      throw InvalidArgument(what + ": " + e.what);
    }
  }
  std::vector<GroundPlan> ours;
  for (std::size_t i = 0, n = py::len(plans); i < n; ++i) {
    const std::string what = "plan " + std::to_string(i);
    const auto v = bytes_view(PyList_GET_ITEM(plans.ptr(), static_cast<Py_ssize_t>(i)), what);
    std::vector<Polygon> polys;
    try {
      WkbReader(v.first, v.second).read_footprint(polys);
    } catch (const WkbError& e) {
      throw InvalidArgument(what + ": " + e.what);
    }
    for (Polygon& p : polys) ours.push_back(GroundPlan{std::move(p), i < members.size() ? members[i] : std::vector<std::uint32_t>{}, 0});
  }
  gis::GeosComparison c;
  {
    py::gil_scoped_release release;
    c = gis::compare_with_geos(fps, ours);
  }
  using V = gis::GeosComparison::Verdict;
  py::dict r;
  r["verdict"] = c.verdict() == V::Match ? "match" : c.verdict() == V::MatchGeosDiffers ? "match_geos_differs" : "mismatch";
  r["match"] = c.matches();
  r["line"] = c.verdict_line();
  r["summary"] = c.summary();
  r["area_m2"] = c.area_ours;
  r["area_geos_m2"] = c.area_geos;
  r["symdiff_area_m2"] = c.symdiff_area;
  r["polygons"] = c.polygons_ours;
  r["polygons_geos"] = c.polygons_geos;
  r["holes"] = c.holes_ours;
  r["holes_geos"] = c.holes_geos;
  r["holes_geos_artifacts"] = c.holes_geos_artifacts;
  r["holes_geos_dropped"] = c.holes_geos_dropped;
  r["invalid"] = c.invalid_ours;
  r["overlapping_pairs"] = c.overlapping_ours;
  r["places_geos_wrong"] = c.places_geos_wrong;
  r["largest_geos_wrong_m2"] = c.largest_geos_wrong_m2;
  r["places_ours_wrong"] = c.places_ours_wrong;
  r["largest_ours_wrong_m2"] = c.largest_ours_wrong_m2;
  r["places_ours_below_pitch"] = c.places_ours_below_pitch;
  r["places_undecided"] = c.places_undecided;
  r["first_ours_wrong"] = c.first_ours_wrong;
  return r;
}

PYBIND11_MODULE(_groundplan, m) {
  m.doc() = "groundplan's compiled core; use the `groundplan` package, which wraps it.";
  static py::exception<Cancelled> cancelled(m, "Cancelled", PyExc_Exception);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Cancelled& e) {
      PyErr_SetString(cancelled.ptr(), e.what());
    } catch (const InvalidArgument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const NotPolygonal& e) {
      PyErr_SetString(PyExc_TypeError, e.what());
    } catch (const Error& e) {  // TopologyError, GpuError
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });
  m.def("union_wkb", &union_wkb, py::arg("wkbs"), py::arg("geos_out") = false, py::arg("threads"), py::arg("resolution"), py::arg("device"),
        py::arg("snap"), py::arg("close_gaps"), py::arg("simplify"), py::arg("min_hole_area"), py::arg("min_area"),
        py::arg("progress"),
        "union_wkb(wkbs: list[bytes], ...) -> dict(plans=[WKB], members=[[int]], areas=[float], problems=[dict], timings=dict);\n"
        "geos_out=True: plans are the addresses of GEOS polygons of this module's libgeos_c, owned by the caller");
  m.def("union_geos", &union_geos, py::arg("addresses"), py::arg("geos_out") = false, py::arg("threads"), py::arg("resolution"), py::arg("device"),
        py::arg("snap"), py::arg("close_gaps"), py::arg("simplify"), py::arg("min_hole_area"), py::arg("min_area"),
        py::arg("progress"),
        "union_geos(addresses: list[int], ...): as union_wkb, from the addresses of GEOS geometries of the same libgeos_c");
  m.def("geos_version_address", [] { return reinterpret_cast<std::uintptr_t>(&GEOSversion); },
        "The address of GEOSversion in the libgeos_c this module uses (Shapely's must be the same for union_geos)");
  m.def(
      "destroy_geos",
      [](const std::vector<std::uintptr_t>& addresses) {
        for (std::uintptr_t a : addresses)
          if (a) GEOSGeom_destroy_r(geos_handle(), reinterpret_cast<GEOSGeometry*>(a));
      },
      py::arg("addresses"), "Frees GEOS geometries given by union_*(geos_out=True) that no Shapely object took over");
  m.def("shapely2_geometries", &shapely2_geometries, py::arg("addresses"),
        "Shapely 2 objects owning the GEOS polygons given by union_*(geos_out=True), made by Shapely's C API");
  m.def("geos_version_address_in", &geos_version_address_in, py::arg("path"),
        "The address of GEOSversion that the loaded shared object `path` binds (0 if not loaded)");
  m.def("verify_wkb", &verify_wkb, py::arg("footprints"), py::arg("plans"), py::arg("members"), py::arg("ids"),
        "verify_wkb(footprints: list[bytes], plans: list[bytes], members: list[list[int]], ids: list[str]) -> dict: "
        "groundplan --verify (verdict, line, the counts of --stats' verify)");
  m.def("read", &read_inputs, py::arg("inputs"), py::arg("options"), py::arg("progress"),
        "read(inputs: list[str], options: dict[str, str], progress) -> dict(layers=..., crs_wkt=..., crs_name=..., stats=...)");
}

// SPDX-License-Identifier: MIT
// Pipeline results on disk, for GROUNDPLAN_CACHE_DIR (result_store.h says what and why).
#include "result_store.h"

#include <cpl_conv.h>
#include <cpl_error.h>

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <type_traits>

namespace groundplan::driver {
namespace {

namespace fs = std::filesystem;

// A field added to these types must be stored too: these fail to compile until the writer and reader follow.
static_assert(sizeof(Footprint) == sizeof(std::vector<Polygon>) + 4 * sizeof(std::string) + 2 * sizeof(double));
static_assert(sizeof(GroundPlan) == sizeof(Polygon) + sizeof(std::vector<std::uint32_t>) + sizeof(double));
static_assert(sizeof(Problem) == 5 * sizeof(std::string));
static_assert(std::is_trivially_copyable_v<Point2> && sizeof(Point2) == 2 * sizeof(double));

constexpr char kMagic[8] = {'G', 'P', 'R', 'E', 'S', 'U', '0', '2'};  // 02: Footprint::parent_id, files read

/// 64-bit FNV-1a: names the file only; the key inside decides.
std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

fs::path file_for(const std::string& dir, const std::string& key) {
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.gpresult", static_cast<unsigned long long>(fnv1a(key)));
  return fs::path(dir) / name;
}

class Writer {
 public:
  explicit Writer(std::ofstream& out) : out_(out) {}
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.write(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void str(const std::string& s) {
    pod<std::uint64_t>(s.size());
    out_.write(s.data(), static_cast<std::streamsize>(s.size()));
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod<std::uint64_t>(v.size());
    out_.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
  }
  void polygon(const Polygon& p) {
    vec(p.outer);
    pod<std::uint64_t>(p.holes.size());
    for (const Ring& h : p.holes) vec(h);
  }

 private:
  std::ofstream& out_;
};

/// Reads what Writer wrote from a buffer; every read checks the bounds (a cut or damaged file: ok() false).
class Reader {
 public:
  Reader(const char* data, std::size_t size) : p_(data), end_(data + size) {}
  bool ok() const { return ok_; }
  bool at_end() const { return p_ == end_; }
  template <class T>
  T pod() {
    T v{};
    if (!take(sizeof v)) return v;
    std::memcpy(&v, p_ - sizeof v, sizeof v);
    return v;
  }
  std::string str() {
    const auto n = count(1);
    if (!take(n)) return {};
    return std::string(p_ - n, n);
  }
  template <class T>
  std::vector<T> vec() {
    const auto n = count(sizeof(T));
    std::vector<T> v(n);
    if (take(n * sizeof(T)) && n) std::memcpy(v.data(), p_ - n * sizeof(T), n * sizeof(T));
    return v;
  }
  Polygon polygon() {
    Polygon p;
    p.outer = vec<Point2>();
    p.holes.resize(count(sizeof(std::uint64_t)));
    for (Ring& h : p.holes) h = vec<Point2>();
    return p;
  }
  /// An element count that the rest of the file can hold (at least `min_bytes` each), else 0 and not ok.
  std::size_t count(std::size_t min_bytes) {
    const auto n = pod<std::uint64_t>();
    if (!ok_ || n > static_cast<std::uint64_t>(end_ - p_) / (min_bytes ? min_bytes : 1)) {
      ok_ = false;
      return 0;
    }
    return static_cast<std::size_t>(n);
  }

 private:
  bool take(std::size_t n) {
    if (!ok_ || static_cast<std::size_t>(end_ - p_) < n) {
      ok_ = false;
      return false;
    }
    p_ += n;
    return true;
  }
  const char* p_;
  const char* end_;
  bool ok_ = true;
};

}  // namespace

std::string result_store_dir() {
  const char* dir = CPLGetConfigOption("GROUNDPLAN_CACHE_DIR", nullptr);
  return dir ? dir : "";
}

std::optional<gis::PipelineResult> load_result(const std::string& dir, const std::string& key, std::string* stamps) {
  const fs::path path = file_for(dir, key);
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (data.size() < sizeof kMagic || std::memcmp(data.data(), kMagic, sizeof kMagic) != 0) {
    CPLDebug("GroundPlan", "%s is not a result file: ignored", path.c_str());
    return std::nullopt;
  }
  Reader r(data.data() + sizeof kMagic, data.size() - sizeof kMagic);
  if (r.str() != key || !r.ok()) {
    CPLDebug("GroundPlan", "%s holds another key: ignored", path.c_str());
    return std::nullopt;
  }
  const std::string stored_stamps = r.str();
  gis::PipelineResult res;
  res.files_read.resize(r.count(1));
  for (std::string& f : res.files_read) f = r.str();
  res.footprints.resize(r.count(1));
  for (Footprint& f : res.footprints) {
    f.polygons.resize(r.count(1));
    for (Polygon& p : f.polygons) p = r.polygon();
    f.source_id = r.str();
    f.source_file = r.str();
    f.method = r.str();
    f.min_z = r.pod<double>();
    f.max_z = r.pod<double>();
    f.parent_id = r.str();
  }
  res.plans.resize(r.count(1));
  for (GroundPlan& g : res.plans) {
    g.polygon = r.polygon();
    g.members = r.vec<std::uint32_t>();
    g.area_m2 = r.pod<double>();
  }
  res.problems.resize(r.count(1));
  for (Problem& p : res.problems) {
    p.source_id = r.str();
    p.file = r.str();
    p.stage = r.str();
    p.code = r.str();
    p.reason = r.str();
  }
  res.buildings_read = r.pod<std::uint64_t>();
  res.buildings_dropped = r.pod<std::uint64_t>();
  res.blocks = r.pod<std::uint64_t>();
  res.raster_backend = r.str();
  res.crs_wkt = r.str();
  res.crs_name = r.str();
  if (!r.ok() || !r.at_end()) {
    CPLDebug("GroundPlan", "%s is cut or damaged: ignored", path.c_str());
    return std::nullopt;
  }
  if (stamps) *stamps = stored_stamps;
  return res;
}

bool store_result(const std::string& dir, const std::string& key, const gis::PipelineResult& res,
                  const std::string& stamps) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  const fs::path path = file_for(dir, key);
  // A name of this process and call alone: concurrent writers of one key never share a temporary file.
  static std::atomic<unsigned> serial{0};
  const fs::path tmp = path.string() + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(++serial);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      CPLDebug("GroundPlan", "cannot write %s: result not stored", tmp.c_str());
      return false;
    }
    Writer w(out);
    out.write(kMagic, sizeof kMagic);
    w.str(key);
    w.str(stamps);
    w.pod<std::uint64_t>(res.files_read.size());
    for (const std::string& f : res.files_read) w.str(f);
    w.pod<std::uint64_t>(res.footprints.size());
    for (const Footprint& f : res.footprints) {
      w.pod<std::uint64_t>(f.polygons.size());
      for (const Polygon& p : f.polygons) w.polygon(p);
      w.str(f.source_id);
      w.str(f.source_file);
      w.str(f.method);
      w.pod(f.min_z);
      w.pod(f.max_z);
      w.str(f.parent_id);
    }
    w.pod<std::uint64_t>(res.plans.size());
    for (const GroundPlan& g : res.plans) {
      w.polygon(g.polygon);
      w.vec(g.members);
      w.pod(g.area_m2);
    }
    w.pod<std::uint64_t>(res.problems.size());
    for (const Problem& p : res.problems) {
      w.str(p.source_id);
      w.str(p.file);
      w.str(p.stage);
      w.str(p.code);
      w.str(p.reason);
    }
    w.pod<std::uint64_t>(res.buildings_read);
    w.pod<std::uint64_t>(res.buildings_dropped);
    w.pod<std::uint64_t>(res.blocks);
    w.str(res.raster_backend);
    w.str(res.crs_wkt);
    w.str(res.crs_name);
    out.flush();
    if (!out) {
      out.close();
      fs::remove(tmp, ec);
      CPLDebug("GroundPlan", "writing %s failed: result not stored", tmp.c_str());
      return false;
    }
  }
  fs::rename(tmp, path, ec);  // atomic on one file system: readers see the old file or the whole new one
  if (ec) {
    fs::remove(tmp, ec);
    CPLDebug("GroundPlan", "cannot rename %s into place: result not stored", tmp.c_str());
    return false;
  }
  CPLDebug("GroundPlan", "result stored in %s", path.c_str());
  return true;
}

}  // namespace groundplan::driver

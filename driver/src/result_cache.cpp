// SPDX-License-Identifier: MIT
// The process-wide cache of pipeline results behind GROUNDPLAN: opens (result_cache.h says what and why).
#include "result_cache.h"
#include "result_store.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>

#include <dlfcn.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <future>
#include <list>
#include <map>
#include <mutex>
#include <cstring>
#include <system_error>

namespace groundplan::driver {
namespace {

namespace fs = std::filesystem;

/// "size mtime ctime inode" of a file; false when it cannot be stat'ed.
bool file_stamp(const fs::path& p, std::string& out) {
  struct stat st {};
  if (::stat(p.c_str(), &st) != 0) return false;
  out += std::to_string(st.st_size) + ' ' + std::to_string(st.st_mtim.tv_sec) + '.' +
         std::to_string(st.st_mtim.tv_nsec) + ' ' + std::to_string(st.st_ctim.tv_sec) + '.' +
         std::to_string(st.st_ctim.tv_nsec) + ' ' + std::to_string(st.st_ino);
  return true;
}

/// The file a reader's path lives in: the path itself, or for a /vsizip/ or /vsigzip/ path (a KMZ's KML, a
/// model inside a zip) the archive holding it; empty when there is no local file (another /vsi file system).
fs::path local_file_of(const std::string& path) {
  std::string p = path;
  for (const char* prefix : {"/vsizip/", "/vsigzip/"})
    if (p.rfind(prefix, 0) == 0) {
      p.erase(0, std::strlen(prefix));
      if (!p.empty() && p.front() == '{' && p.find('}') != std::string::npos) p.erase(0, 1), p.erase(p.find('}'), 1);
      for (fs::path f(p); !f.empty() && f != f.parent_path(); f = f.parent_path()) {
        std::error_code ec;
        if (fs::is_regular_file(f, ec)) return f;
      }
      return {};
    }
  if (p.rfind("/vsi", 0) == 0) return {};
  return fs::path(p);
}

/// "path\tstamp\n" for each of `files` (the files a result was read from), in order; a file that is gone is
/// "missing". A result is valid while this is what it was when the result was made.
std::string stamps_of(const std::vector<std::string>& files) {
  std::string out;
  for (const std::string& f : files) {
    const fs::path local = local_file_of(f);
    if (local.empty()) continue;
    out += local.string() + '\t';
    if (!file_stamp(local, out)) out += "missing";
    out += '\n';
  }
  return out;
}

std::size_t config_size(const char* name, std::size_t fallback) {
  const char* v = CPLGetConfigOption(name, nullptr);
  if (!v) return fallback;
  const long long n = CPLAtoGIntBig(v);
  return n < 0 ? fallback : static_cast<std::size_t>(n);
}

/// The cache itself: live results (weak, shared by open datasets), computations under way, and an LRU of
/// the last results kept for later opens.
class ResultCache {
 public:
  SharedResult get(const std::string& key, const std::string& what,
                   const std::function<gis::PipelineResult()>& compute) {
    std::unique_lock<std::mutex> lock(mutex_);
    prune();
    auto found = slots_.find(key);
    if (found != slots_.end()) {
      if (SharedResult live = found->second.live.lock()) {
        if (stamps_of(live->files_read) == found->second.stamps) {
          touch(key, live);
          lock.unlock();  // no call out (an error handler may be Python, waiting for its GIL) under the lock
          CPLDebug("GroundPlan", "cached result for %s", what.c_str());
          return live;
        }
        // A file it was read from changed (a linked model, a buffer): computed again. Open datasets keep theirs.
        kept_.remove_if([&](const Kept& k) { return k.key == key; });
        slots_.erase(found);
        found = slots_.end();
      }
    }
    if (found != slots_.end()) {
      if (found->second.pending.valid()) {
        std::shared_future<SharedResult> pending = found->second.pending;
        lock.unlock();
        CPLDebug("GroundPlan", "waiting for the pipeline run of another open of %s", what.c_str());
        return pending.get();  // rethrows the computation's exception
      }
    }
    std::promise<SharedResult> promise;
    slots_[key].pending = promise.get_future().share();
    lock.unlock();
    SharedResult result;
    std::string stamps;
    try {
      result = produce(key, what, compute, stamps);
    } catch (...) {
      lock.lock();
      slots_.erase(key);
      lock.unlock();
      promise.set_exception(std::current_exception());
      throw;
    }
    lock.lock();
    Slot& slot = slots_[key];
    slot.live = result;
    slot.stamps = std::move(stamps);
    slot.pending = {};
    touch(key, result);
    lock.unlock();
    promise.set_value(result);
    return result;
  }

  static SharedResult run(const std::string& what, const std::function<gis::PipelineResult()>& compute) {
    const std::size_t n = ++runs_;
    CPLDebug("GroundPlan", "pipeline run %zu for %s", n, what.c_str());
    return std::make_shared<const gis::PipelineResult>(compute());
  }

  static std::size_t runs() { return runs_.load(); }

  /// From GROUNDPLAN_CACHE_DIR when it holds `key` and the files it was read from are as they were then, else
  /// computed (and stored there when it is set). `stamps`: those files' stamps (stamps_of).
  static SharedResult produce(const std::string& key, const std::string& what,
                              const std::function<gis::PipelineResult()>& compute, std::string& stamps) {
    const std::string dir = result_store_dir();
    if (!dir.empty()) {
      std::string stored_stamps;
      if (std::optional<gis::PipelineResult> stored = load_result(dir, key, &stored_stamps)) {
        stamps = stamps_of(stored->files_read);
        if (stamps == stored_stamps) {
          CPLDebug("GroundPlan", "result for %s read from %s", what.c_str(), dir.c_str());
          return std::make_shared<const gis::PipelineResult>(std::move(*stored));
        }
        CPLDebug("GroundPlan", "result for %s in %s was read from files changed since: ignored", what.c_str(), dir.c_str());
      }
    }
    SharedResult result = run(what, compute);
    stamps = stamps_of(result->files_read);
    if (!dir.empty()) store_result(dir, key, *result, stamps);
    return result;
  }

 private:
  struct Slot {
    std::weak_ptr<const gis::PipelineResult> live;
    std::string stamps;  // of the files the result was read from, when it was made (stamps_of)
    std::shared_future<SharedResult> pending;
  };
  struct Kept {
    std::string key;
    SharedResult result;
    std::size_t bytes;
  };

  /// `key` becomes the most recently used kept result; the oldest go while over the bounds.
  void touch(const std::string& key, const SharedResult& result) {
    auto it = std::find_if(kept_.begin(), kept_.end(), [&](const Kept& k) { return k.key == key; });
    if (it != kept_.end()) {
      kept_.splice(kept_.begin(), kept_, it);
    } else {
      kept_.push_front({key, result, result_bytes(*result)});
    }
    const std::size_t max_entries = config_size("GROUNDPLAN_CACHE_ENTRIES", 4);
    const std::size_t max_bytes = config_size("GROUNDPLAN_CACHE_MAX_MB", 1024) << 20;
    std::size_t bytes = 0, entries = 0;
    for (auto k = kept_.begin(); k != kept_.end();) {
      if (entries + 1 > max_entries || bytes + k->bytes > max_bytes) {
        k = kept_.erase(k);  // a dataset still open keeps it alive; `live` finds it then
      } else {
        bytes += k->bytes;
        ++entries;
        ++k;
      }
    }
  }

  /// Drops the slots of results no dataset holds any more and no computation fills.
  void prune() {
    for (auto it = slots_.begin(); it != slots_.end();)
      it = it->second.live.expired() && !it->second.pending.valid() ? slots_.erase(it) : std::next(it);
  }

  std::mutex mutex_;
  std::map<std::string, Slot> slots_;
  std::list<Kept> kept_;  // most recently used first
  static inline std::atomic<std::size_t> runs_{0};
};

ResultCache& cache() {
  static ResultCache* c = new ResultCache();  // never destroyed: datasets may close after static destruction
  return *c;
}

/// The file holding this code (the plugin, the Python module or a program linking the driver statically), with
/// its stamp: the pipeline is compiled into it, so another build is another key.
std::string build_identity() {
  Dl_info info{};
  std::string id = "build\t";
  if (dladdr(reinterpret_cast<void*>(&build_identity), &info) && info.dli_fname) {
    id += info.dli_fname;
    id += '\t';
    if (!file_stamp(info.dli_fname, id)) id += "unknown";
  }
  return id + '\n';
}

}  // namespace

std::string result_cache_key(const std::vector<std::string>& inputs, char** open_options) {
  if (!CPLTestBool(CPLGetConfigOption("GROUNDPLAN_CACHE", "YES"))) return {};
  std::string key = build_identity();
  for (const std::string& input : inputs) {
    if (STARTS_WITH(input.c_str(), "/vsi")) return {};
    std::error_code ec;
    const fs::path canonical = fs::canonical(input, ec);
    if (ec) return {};  // not a local file or folder: a database, a URL ...
    key += "input\t" + canonical.string() + '\n';
    // The files it names (a folder: its input files; another file written beside them is none of them) as they
    // are now; what they link is checked against the result's files_read when the result is reused.
    std::vector<std::string> files;
    try {
      files = gis::input_files({canonical.string()});
    } catch (const std::exception&) {
      return {};  // the run says why
    }
    if (files.size() > kMaxTrackedFiles) return {};
    key += stamps_of(files);
  }
  std::vector<std::string> options;
  for (CSLConstList o = open_options; o && *o; ++o) {
    char* name = nullptr;
    const char* value = CPLParseNameValue(*o, &name);
    if (name && value && !EQUAL(name, "NUM_THREADS")) options.push_back(CPLString(name).toupper() + '=' + value);
    CPLFree(name);
  }
  std::sort(options.begin(), options.end());
  for (const std::string& o : options) key += "option\t" + o + '\n';
  return key;
}

SharedResult cached_pipeline_result(const std::string& key, const std::string& what,
                                    const std::function<gis::PipelineResult()>& compute) {
  if (key.empty()) return ResultCache::run(what, compute);
  return cache().get(key, what, compute);
}

std::size_t pipeline_runs() { return ResultCache::runs(); }

std::size_t result_bytes(const gis::PipelineResult& r) {
  auto polygon = [](const Polygon& p) {
    std::size_t n = p.outer.capacity();
    for (const Ring& h : p.holes) n += h.capacity();
    return n * sizeof(Point2) + (p.holes.size() + 1) * sizeof(Ring);
  };
  std::size_t bytes = sizeof(r);
  for (const Footprint& f : r.footprints) {
    bytes += sizeof(f) + f.source_id.capacity() + f.source_file.capacity() + f.method.capacity();
    for (const Polygon& p : f.polygons) bytes += polygon(p);
  }
  for (const GroundPlan& g : r.plans) bytes += sizeof(g) + polygon(g.polygon) + g.members.capacity() * 4;
  for (const Problem& p : r.problems)
    bytes += sizeof(p) + p.source_id.size() + p.file.size() + p.stage.size() + p.code.size() + p.reason.size();
  return bytes;
}

}  // namespace groundplan::driver

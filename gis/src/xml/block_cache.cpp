// SPDX-License-Identifier: MIT
#include "xml/block_cache.h"

#include <pugixml.hpp>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <vector>

namespace groundplan::gis::xml {
namespace {

// Every block starts with its whole size (header included), so that cached_free knows it; 16 bytes keep
// the pointer handed out aligned as malloc's.
constexpr std::size_t kHeader = 16;
// Smaller blocks are malloc's business (its bins reuse them without faults).
constexpr std::size_t kMinCached = std::size_t(16) << 10;
constexpr std::size_t kPage = std::size_t(4) << 10, kLarge = std::size_t(1) << 20;

std::size_t block_size(std::size_t n) {
  const std::size_t total = n + kHeader;
  if (total < kMinCached) return total;
  const std::size_t unit = total >= kLarge ? kLarge : kPage;
  return (total + unit - 1) / unit * unit;
}

class Cache;
struct Registry {
  std::mutex m;
  std::vector<Cache*> caches;
};
Registry& registry() {
  static Registry* r = new Registry;  // never destroyed: threads may end after static destruction began
  return *r;
}

class Cache {
 public:
  Cache() {
    std::lock_guard<std::mutex> g(registry().m);
    registry().caches.push_back(this);
  }
  ~Cache() {
    {
      std::lock_guard<std::mutex> g(registry().m);
      auto& c = registry().caches;
      c.erase(std::remove(c.begin(), c.end(), this), c.end());
    }
    release();
  }
  /// A cached block of `size` (a large one may be up to half as large again), or nullptr.
  void* take(std::size_t size) {
    std::lock_guard<std::mutex> g(m_);
    const std::size_t most = size >= kLarge ? size + size / 2 : size;
    for (std::size_t k = free_.size(); k-- > 0;) {
      if (free_[k].size < size || free_[k].size > most) continue;
      void* raw = free_[k].raw;
      bytes_ -= free_[k].size;
      free_[k] = free_.back();
      free_.pop_back();
      return raw;
    }
    return nullptr;
  }
  /// Keeps `raw` when there is room, else frees it.
  void put(void* raw, std::size_t size) {
    {
      std::lock_guard<std::mutex> g(m_);
      if (bytes_ + size <= kCachedBytesPerThread) {
        free_.push_back(Block{size, raw});
        bytes_ += size;
        return;
      }
    }
    std::free(raw);
  }
  void release() {
    std::vector<Block> blocks;
    {
      std::lock_guard<std::mutex> g(m_);
      blocks.swap(free_);
      bytes_ = 0;
    }
    for (const Block& b : blocks) std::free(b.raw);
  }
  std::size_t bytes() {
    std::lock_guard<std::mutex> g(m_);
    return bytes_;
  }

 private:
  struct Block {
    std::size_t size;
    void* raw;
  };
  std::mutex m_;  // release_cached_blocks() may come from another thread
  std::vector<Block> free_;
  std::size_t bytes_ = 0;
};

Cache& this_thread_cache() {
  thread_local Cache cache;
  return cache;
}

void* pugixml_allocate(std::size_t n) { return cached_alloc(n); }
void pugixml_deallocate(void* p) { cached_free(p); }

}  // namespace

void* cached_alloc(std::size_t n) {
  if (n > static_cast<std::size_t>(-1) / 2) return nullptr;
  const std::size_t size = block_size(n);
  void* raw = size >= kMinCached ? this_thread_cache().take(size) : nullptr;
  if (!raw) raw = std::malloc(size);
  if (!raw) return nullptr;
  *static_cast<std::size_t*>(raw) = size;
  return static_cast<char*>(raw) + kHeader;
}

void cached_free(void* p) {
  if (!p) return;
  void* raw = static_cast<char*>(p) - kHeader;
  const std::size_t size = *static_cast<std::size_t*>(raw);
  if (size < kMinCached)
    std::free(raw);
  else
    this_thread_cache().put(raw, size);
}

void release_cached_blocks() {
  std::lock_guard<std::mutex> g(registry().m);
  for (Cache* c : registry().caches) c->release();
}

std::size_t cached_bytes() {
  std::lock_guard<std::mutex> g(registry().m);
  std::size_t n = 0;
  for (Cache* c : registry().caches) n += c->bytes();
  return n;
}

void use_block_cache_for_pugixml() {
  static std::once_flag once;
  std::call_once(once, [] { pugi::set_memory_management_functions(pugixml_allocate, pugixml_deallocate); });
}

}  // namespace groundplan::gis::xml

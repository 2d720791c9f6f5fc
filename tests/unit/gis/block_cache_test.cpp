// SPDX-License-Identifier: MIT
// The memory kept per thread for documents parsed in memory (gis/src/xml/block_cache.h): a freed block
// comes back for the next document of the same size, nothing past the per-thread bound is kept, what a
// thread keeps is freed when it ends and when the pipeline asks, and pugixml parses through it.
#include <gtest/gtest.h>

#include "xml/block_cache.h"
#include "xml/dom_events.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace groundplan::gis::xml {
namespace {

constexpr std::size_t kMiB = std::size_t(1) << 20;

TEST(BlockCache, AFreedBlockIsHandedOutAgainForTheSameSize) {
  release_cached_blocks();
  void* a = cached_alloc(8 * kMiB + 123);
  ASSERT_NE(a, nullptr);
  std::memset(a, 1, 8 * kMiB + 123);  // the whole size is usable
  cached_free(a);
  EXPECT_GE(cached_bytes(), 8 * kMiB);
  void* b = cached_alloc(8 * kMiB);  // a little smaller: the same block
  EXPECT_EQ(a, b);
  EXPECT_EQ(cached_bytes(), 0u);
  void* c = cached_alloc(16 * kMiB);  // twice as large: not that block
  EXPECT_NE(c, b);
  cached_free(b);
  cached_free(c);
  release_cached_blocks();
  EXPECT_EQ(cached_bytes(), 0u);
}

TEST(BlockCache, PagesOfTheTreeAreReusedAndAligned) {
  release_cached_blocks();
  std::vector<void*> pages;
  for (int k = 0; k < 100; ++k) {
    pages.push_back(cached_alloc(32 * 1024 + 40));  // a pugixml page
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(pages.back()) % 16, 0u);
  }
  for (void* p : pages) cached_free(p);
  const std::size_t kept = cached_bytes();
  EXPECT_GE(kept, 100u * (32 * 1024 + 40));
  for (int k = 0; k < 100; ++k) pages[k] = cached_alloc(32 * 1024 + 40);
  EXPECT_EQ(cached_bytes(), 0u);
  for (void* p : pages) cached_free(p);
  release_cached_blocks();
}

TEST(BlockCache, SmallBlocksAreLeftToMalloc) {
  release_cached_blocks();
  void* p = cached_alloc(100);
  ASSERT_NE(p, nullptr);
  cached_free(p);
  EXPECT_EQ(cached_bytes(), 0u);
  cached_free(nullptr);  // a no-op
  EXPECT_EQ(cached_alloc(static_cast<std::size_t>(-1) - 4), nullptr);  // absurd sizes fail, no overflow
}

TEST(BlockCache, NoThreadKeepsMoreThanItsBound) {
  release_cached_blocks();
  std::vector<void*> blocks;
  for (std::size_t k = 0; k < kCachedBytesPerThread / (8 * kMiB) + 4; ++k) blocks.push_back(cached_alloc(8 * kMiB));
  for (void* p : blocks) cached_free(p);
  EXPECT_LE(cached_bytes(), kCachedBytesPerThread);
  EXPECT_GE(cached_bytes(), kCachedBytesPerThread - 9 * kMiB);
  release_cached_blocks();
}

TEST(BlockCache, AThreadsBlocksAreFreedWhenItEnds) {
  release_cached_blocks();
  std::size_t kept_inside = 0;
  void* from_main = cached_alloc(4 * kMiB);
  std::thread t([&] {
    cached_free(from_main);  // freed by another thread: joins that thread's cache
    cached_free(cached_alloc(2 * kMiB));
    kept_inside = cached_bytes();
  });
  t.join();
  EXPECT_GE(kept_inside, 6 * kMiB);
  EXPECT_EQ(cached_bytes(), 0u);
}

TEST(BlockCache, PugixmlParsesThroughTheCacheAndGivesItsMemoryBack) {
  release_cached_blocks();
  std::string doc = "<r xmlns=\"u\">";
  for (int k = 0; k < 20000; ++k) doc += "<a b=\"" + std::to_string(k) + "\">t</a>";
  doc += "</r>";
  {
    DomEvents dom;  // makes pugixml allocate here
    ASSERT_EQ(dom.load(doc.data(), doc.size()), "");
  }
  const std::size_t kept = cached_bytes();
  EXPECT_GE(kept, doc.size());  // at least its copy of the document came back
  {
    DomEvents dom;
    ASSERT_EQ(dom.load(doc.data(), doc.size()), "");
    EXPECT_LT(cached_bytes(), kept);  // taken again for the second parse
  }
  release_cached_blocks();
  EXPECT_EQ(cached_bytes(), 0u);
}

}  // namespace
}  // namespace groundplan::gis::xml

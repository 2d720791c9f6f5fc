// SPDX-License-Identifier: MIT
#pragma once
// Memory for CityGML documents parsed in memory (dom_events.h), kept per thread from one document to the
// next. A chunk of 8 MiB costs about three times its size (its bytes, pugixml's copy, the tree's pages),
// all freed when the chunk is done; from glibc's malloc that memory comes back as fresh pages every time
// (a thread's heap grows and is trimmed again, large blocks are mapped and unmapped), and each fresh page
// is a fault the kernel zeroes under the process's memory lock: a third of the reading threads' time on
// the 2-core VM, and a lock all 16 threads queue on at city scale (tests/bench/RESULTS.md, "Reading
// memory kept per thread"). Blocks freed here go to the calling thread's cache instead, up to
// kCachedBytesPerThread, and are handed out again by size.
#include <cstddef>

namespace groundplan::gis::xml {

/// At most this much freed memory is kept by one thread (about two 8 MiB chunks' worth).
inline constexpr std::size_t kCachedBytesPerThread = std::size_t(64) << 20;

/// n bytes (aligned as malloc's), from the calling thread's cache when a block of the size is there;
/// nullptr when memory is exhausted.
void* cached_alloc(std::size_t n);
/// Gives back a block of cached_alloc (any thread may; it joins the calling thread's cache). nullptr: no-op.
void cached_free(void* p);
/// Frees what every thread's cache holds (the pipeline calls it when reading is done, so that the
/// union and the writer do not run beside memory nobody uses).
void release_cached_blocks();
/// Bytes held by all caches now (for the tests).
std::size_t cached_bytes();

/// Makes pugixml allocate through cached_alloc / cached_free. Idempotent; called before the first
/// pugixml document is made (DomEvents' constructor).
void use_block_cache_for_pugixml();

}  // namespace groundplan::gis::xml

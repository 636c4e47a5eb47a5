// InstancePool: per-class free lists and chunks of a SimState's instances.
#include "vsd/core/detail/instance_pool.hpp"

#include <algorithm>
#include <cstdint>

#include "vsd/core/detail/huge_pages.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace vsd::detail {

// ---- huge pages (huge_pages.hpp; here, with the pool, their first user) ----------------------------------

void advise_huge_pages(void* p, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t page = huge_page_bytes;
  const auto from = reinterpret_cast<std::uintptr_t>(p);
  const auto first = (from + page - 1) & ~(page - 1);
  const auto last = (from + bytes) & ~(page - 1);
  // Fails (EINVAL) where the kernel has no transparent huge pages: the memory is used as it is.
  if (last > first) (void)::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

void* allocate_big(std::size_t bytes, std::size_t align) {
  if (bytes < huge_block_bytes) {
    return align <= __STDCPP_DEFAULT_NEW_ALIGNMENT__ ? ::operator new(bytes)
                                                     : ::operator new(bytes, std::align_val_t(align));
  }
  // Aligned to a huge page, so that every huge page of it can be one (malloc gives such a block fresh
  // pages of its own, untouched: the advice comes before the first fault).
  void* p = ::operator new(bytes, std::align_val_t(std::max(align, huge_page_bytes)));
  advise_huge_pages(p, bytes);
  return p;
}

void free_big(void* p, std::size_t bytes, std::size_t align) noexcept {
  if (bytes < huge_block_bytes) {
    if (align <= __STDCPP_DEFAULT_NEW_ALIGNMENT__)
      ::operator delete(p);
    else
      ::operator delete(p, std::align_val_t(align));
    return;
  }
  ::operator delete(p, std::align_val_t(std::max(align, huge_page_bytes)));
}

// ---- InstancePool -----------------------------------------------------------------------------------------

namespace {
// Chunks start small (a state with a handful of instances of a class wastes little) and double up to
// about 64 KiB, so that a big population costs one allocation per few hundred instances.
constexpr std::size_t first_chunk = 4;
constexpr std::size_t chunk_bytes_cap = std::size_t{64} * 1024;
}  // namespace

InstancePool::PerClass& InstancePool::per_class(const MetaInstance& cls) {
  if (classes_.size() <= cls.index()) classes_.resize(cls.index() + 1);
  PerClass& c = classes_[cls.index()];
  if (c.stride == 0) {
    // A block also carries the free-list link while it is free.
    c.align = std::max(cls.alignment(), alignof(void*));
    c.stride = (std::max(cls.size(), sizeof(void*)) + c.align - 1) / c.align * c.align;
    c.chunk = first_chunk;
  }
  return c;
}

void InstancePool::add_chunk(PerClass& c, std::size_t count) {
  // The rest of the current chunk goes to the free list, so that nothing is lost.
  while (c.next != c.end) {
    void* p = c.next;
    c.next += c.stride;
    *static_cast<void**>(p) = c.free;
    c.free = p;
    VSD_POOL_POISON(p, c.stride);
  }
  chunks_.reserve(chunks_.size() + 1);  // nothing below may fail after the allocation
  const std::size_t bytes = c.stride * count;
  void* memory = allocate_big(bytes, c.align);
  chunks_.push_back(Chunk{memory, bytes, c.align});
  c.next = static_cast<char*>(memory);
  c.end = c.next + bytes;
}

void* InstancePool::refill(const MetaInstance& cls) {
  PerClass& c = per_class(cls);
  if (c.free == nullptr && c.next == c.end) {
    add_chunk(c, c.chunk);
    if (c.chunk * 2 * c.stride <= chunk_bytes_cap) c.chunk *= 2;
  }
  return allocate(cls);
}

void InstancePool::reserve(const MetaInstance& cls, std::size_t count) {
  // Up to huge_block_bytes, room comes in chunks of at most chunk_bytes_cap, not in one block for all:
  // chunks that size come from (and go back to) the allocator's heap, where one block would be fresh
  // pages from the kernel, faulted in one by one, on every load. Beyond it the memory is fresh pages
  // anyway (the heap would grow by as much): one chunk for all, in huge pages where the system has them.
  PerClass& c = per_class(cls);
  if (count >= huge_block_bytes / c.stride && c.free == nullptr) {  // (a free list is used up first)
    if (static_cast<std::size_t>(c.end - c.next) / c.stride < count) add_chunk(c, count);
    return;
  }
  const std::size_t cap = std::max<std::size_t>(1, chunk_bytes_cap / c.stride);
  c.chunk = std::max(c.chunk, std::min(count, cap));
}

void InstancePool::release() noexcept {
  for (const Chunk& k : chunks_) {
    VSD_POOL_UNPOISON(k.memory, k.bytes);
    free_big(k.memory, k.bytes, k.align);
  }
  chunks_.clear();
  classes_.clear();
}

}  // namespace vsd::detail

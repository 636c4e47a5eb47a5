// InstancePool: per-class free lists and chunks of a SimState's instances.
#include "vsd/core/detail/instance_pool.hpp"

#include <algorithm>

namespace vsd::detail {

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
  void* memory = ::operator new(bytes, std::align_val_t(c.align));
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
  // Room comes in chunks of at most chunk_bytes_cap, not in one block for all: chunks that size come
  // from (and go back to) the allocator's heap, where one huge block would be fresh pages from the
  // kernel, faulted in one by one, on every load.
  PerClass& c = per_class(cls);
  const std::size_t cap = std::max<std::size_t>(1, chunk_bytes_cap / c.stride);
  c.chunk = std::max(c.chunk, std::min(count, cap));
}

void InstancePool::release() noexcept {
  for (const Chunk& k : chunks_) {
    VSD_POOL_UNPOISON(k.memory, k.bytes);
    ::operator delete(k.memory, std::align_val_t(k.align));
  }
  chunks_.clear();
  classes_.clear();
}

}  // namespace vsd::detail

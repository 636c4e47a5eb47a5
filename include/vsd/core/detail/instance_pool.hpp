/** @file
 *  @brief Internal: InstancePool, the memory of one SimState's instances — per class, a free list of the
 *  blocks of deleted instances, refilled from chunks that hold many instances back to back.
 *
 *  Creating an instance then costs a pop from a list instead of a call to the allocator, and deleting
 *  it a push; instances made together (a load) lie together in memory. Memory goes back to the system
 *  when the pool dies with its SimState, not when an instance is deleted: a state that shrinks keeps
 *  the blocks for its next instances of the same class. Blocks are keyed by MetaInstance::index(), so a
 *  run-time class of any size and alignment gets blocks of its own size, and a pool never needs the
 *  class itself again (a run-time class may be undefined while its blocks wait in the pool).
 *
 *  Under AddressSanitizer a free block is poisoned, so that a use after delete is still reported.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

#include "vsd/core/config.hpp"
#include "vsd/core/meta_instance.hpp"

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#define VSD_POOL_POISON(p, n) ASAN_POISON_MEMORY_REGION((p), (n))
#define VSD_POOL_UNPOISON(p, n) ASAN_UNPOISON_MEMORY_REGION((p), (n))
#else
#define VSD_POOL_POISON(p, n) ((void)(p), (void)(n))
#define VSD_POOL_UNPOISON(p, n) ((void)(p), (void)(n))
#endif

namespace vsd::detail {

class InstancePool {
 public:
  InstancePool() = default;
  InstancePool(const InstancePool&) = delete;
  InstancePool& operator=(const InstancePool&) = delete;
  ~InstancePool() { release(); }

  /// Uninitialised memory for one instance of @p cls (cls.size() bytes, cls.alignment() aligned).
  void* allocate(const MetaInstance& cls) {
    if (VSD_LIKELY(cls.index() < classes_.size())) {
      PerClass& c = classes_[cls.index()];
      if (VSD_LIKELY(c.free != nullptr)) {
        void* p = c.free;
        VSD_POOL_UNPOISON(p, c.stride);
        c.free = *static_cast<void**>(p);
        return p;
      }
      if (VSD_LIKELY(c.next != c.end)) {
        void* p = c.next;
        c.next += c.stride;
        return p;
      }
    }
    return refill(cls);
  }

  /// Gives back the block of an instance of @p cls that was destroyed (its destructors have run).
  void deallocate(const MetaInstance& cls, void* p) noexcept {
    PerClass& c = classes_[cls.index()];
    *static_cast<void**>(p) = c.free;
    c.free = p;
    VSD_POOL_POISON(p, c.stride);
  }

  /// Prepares for @p count more instances of @p cls (a loader that knows its count): the next chunks
  /// are made as big as the pool allows.
  void reserve(const MetaInstance& cls, std::size_t count);

  /// Frees every chunk. Only when no instance lives in the pool any more.
  void release() noexcept;

 private:
  struct PerClass {
    void* free = nullptr;  // blocks of deleted instances, linked through their first word
    char* next = nullptr;  // the unused rest of the newest chunk
    char* end = nullptr;
    std::size_t stride = 0;  // block size: the class's size, rounded up to its alignment
    std::size_t align = 0;
    std::size_t chunk = 0;  // instances in the next chunk (grows)
  };
  struct Chunk {
    void* memory;
    std::size_t bytes;
    std::size_t align;
  };
  PerClass& per_class(const MetaInstance& cls);
  void* refill(const MetaInstance& cls);
  void add_chunk(PerClass& c, std::size_t count);

  std::vector<PerClass> classes_;  // by MetaInstance::index()
  std::vector<Chunk> chunks_;
};

}  // namespace vsd::detail

/** @file
 *  @brief Internal: big blocks of memory backed by huge pages where the system gives them on request
 *  (Linux's transparent huge pages in "madvise" or "always" mode), and HugeAllocator, a std::allocator
 *  for vectors that may become that big (the tables of a load of millions of instances).
 *
 *  Fresh memory from the kernel is faulted in page by page on first touch. For the hundreds of MB a
 *  load of a million instances builds, that is ~100 000 faults of 4 KiB, each several microseconds on a
 *  virtual machine: more than the instances cost to build. In 2 MiB pages it is a few hundred. Only
 *  blocks of at least huge_block_bytes get the advice, so small states and tables use no more memory
 *  than before (a huge page is filled in whole); where the advice is not followed (no THP, another
 *  system), nothing changes.
 */
#pragma once

#include <cstddef>
#include <new>

namespace vsd::detail {

/// From this size on, a block is allocated 2 MiB aligned and advised to use huge pages.
inline constexpr std::size_t huge_block_bytes = std::size_t{8} << 20;
/// The size and alignment of one huge page (x86-64 and most 64-bit systems with THP).
inline constexpr std::size_t huge_page_bytes = std::size_t{2} << 20;

/// Asks for huge pages for the whole huge pages inside [@p p, @p p + @p bytes). Only advice: never fails.
void advise_huge_pages(void* p, std::size_t bytes) noexcept;

/// @p bytes of uninitialised memory aligned to @p align; a block of at least huge_block_bytes is
/// aligned to a huge page and advised to use huge pages. Free it with free_big(p, bytes, align).
/// @throws std::bad_alloc
[[nodiscard]] void* allocate_big(std::size_t bytes, std::size_t align);
/// Frees what allocate_big(@p bytes, @p align) returned.
void free_big(void* p, std::size_t bytes, std::size_t align) noexcept;

/// std::allocator for vectors that may grow to millions of elements: their big blocks come from
/// allocate_big (huge pages), their small ones from plain operator new.
template <class T>
struct HugeAllocator {
  using value_type = T;
  HugeAllocator() noexcept = default;
  template <class U>
  HugeAllocator(const HugeAllocator<U>&) noexcept {}  // NOLINT(google-explicit-constructor)

  [[nodiscard]] T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(allocate_big(n * sizeof(T), alignof(T)));
  }
  void deallocate(T* p, std::size_t n) noexcept { free_big(p, n * sizeof(T), alignof(T)); }

  template <class U>
  friend bool operator==(const HugeAllocator&, const HugeAllocator<U>&) noexcept {
    return true;
  }
};

}  // namespace vsd::detail

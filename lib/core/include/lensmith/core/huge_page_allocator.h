// An allocator for the renderer's frame-sized buffers (sources, layers, splat bands, composites):
// blocks of 2 MiB and more are aligned to 2 MiB, rounded up to whole 2 MiB pages and advised to
// the kernel as transparent huge pages, so that touching them for the first time costs one page
// fault per 2 MiB instead of one per 4 KiB. On a virtual machine a fault is expensive: on the KVM guest of docs/performance.md, first
// touching 256 MiB took 0.84-0.98 s in 4 KiB pages and 0.025 s in huge pages, and a 1080p render
// touches several hundred MiB. Where the kernel has transparent huge pages off, or on other systems,
// the advice is ignored and the allocator behaves like std::allocator.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace lensmith {

// Blocks from this size up are advised as huge pages, rounded up to whole 2 MiB pages: a block of
// 512 KiB faulted in as 128 small pages costs about 1.5 ms on that guest, as one huge page 0.1 ms.
// But a huge page is zeroed whole when first touched, so a block of 1 MiB rounded up to one wasted
// half of it: smaller blocks are left to operator new, which in the command line comes from a heap
// whose first 64 MiB are huge pages already (cli/huge_page_new.cpp), packed without rounding. From
// 512 KiB, the street scene's thin-lens process touched 115 MB and from 2 MiB 95 MB: 138.0 -> 131.7 ms
// at f/1.4 and 107.6 -> 101.0 ms at f/16 (docs/performance.md). Elsewhere (the Python module)
// blocks under 2 MiB are faulted in 4 KiB at a time, as std::allocator's are.
inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;
inline constexpr std::size_t kHugePageFromBytes = std::size_t{2} << 20;

// A block of at least kHugePageFromBytes bytes (the caller checks), 2-MiB aligned, its size rounded
// up to whole huge pages and advised as such; released by std::free. Throws std::bad_alloc.
inline void* allocate_huge_pages(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(-1) - kHugePageBytes) throw std::bad_alloc();
  const std::size_t rounded = (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  void* p = std::aligned_alloc(kHugePageBytes, rounded);
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure leaves ordinary pages
#endif
  return p;
}

template <class T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() noexcept = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>& /*other*/) noexcept {}

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePageFromBytes) return static_cast<T*>(::operator new(bytes, std::align_val_t{alignof(T)}));
    return static_cast<T*>(allocate_huge_pages(bytes));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePageFromBytes) {
      ::operator delete(p, std::align_val_t{alignof(T)});
    } else {
      std::free(p);
    }
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>& /*other*/) const noexcept {
    return true;
  }
};

// A std::vector for frame-sized data (HugePageAllocator).
template <class T>
using LargeVector = std::vector<T, HugePageAllocator<T>>;

// HugePageAllocator, except that an element made without a value (a vector's resize(n) or count
// constructor) is not constructed: for frame-sized arrays whose every element the threads write
// before anything reads it. A constructing resize writes the whole array on one thread first (the
// renderer's 13 MB of sources of a 600 x 400 frame, docs/performance.md). T must be an
// implicit-lifetime type (a scalar, or an aggregate of them such as the renderer's sources), whose
// objects its storage holds before they are written.
template <class T>
struct UnconstructedAllocator : HugePageAllocator<T> {
  UnconstructedAllocator() noexcept = default;
  template <class U>
  UnconstructedAllocator(const UnconstructedAllocator<U>& /*other*/) noexcept {}
  template <class U>
  void construct(U* /*p*/) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// A LargeVector whose resize(n) leaves the new elements to be written (UnconstructedAllocator).
template <class T>
using UnconstructedVector = std::vector<T, UnconstructedAllocator<T>>;

}  // namespace lensmith

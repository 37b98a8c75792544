// Fresh memory faulted in from several threads at once. The kernel zeroes a page in the thread that
// first writes to it, and on a virtual machine that is the dearest part of touching fresh memory:
// the host backs the page too (docs/performance.md measured 0.05 to 2.4 ms a MiB on its KVM guest,
// from hour to hour). A frame-sized buffer filled by one thread (a vector resized, a layer's sources
// copied) paid all of it on that thread.
#pragma once

#include <omp.h>

#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "lensmith/core/huge_page_allocator.h"

namespace lensmith::render_detail {

inline constexpr std::size_t kTouchPageBytes = 4096;

// Faults in the pages of storage[from, to) (bytes; `from` a page boundary) from `threads` threads, a
// contiguous share each. Returns the page boundary at or after `to` (what is faulted in now).
inline std::size_t touch_pages(void* storage, std::size_t from, std::size_t to, int threads) {
  if (to <= from) return from;
  volatile unsigned char* const bytes = static_cast<unsigned char*>(storage);
  const auto pages = static_cast<std::ptrdiff_t>((to - from + kTouchPageBytes - 1) / kTouchPageBytes);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t k = 0; k < pages; ++k) bytes[from + static_cast<std::size_t>(k) * kTouchPageBytes] = 0;
  return from + static_cast<std::size_t>(pages) * kTouchPageBytes;
}

// Makes room in `v` for `count` elements and faults in the pages of that room beyond its elements
// (the storage no element lives in yet) from `threads` threads, a contiguous share each.
template <class T, class Allocator>
void fault_in(std::vector<T, Allocator>& v, std::size_t count, int threads) {
  if (count > v.capacity()) v.reserve(count);
  const std::size_t from = (v.size() * sizeof(T) + kTouchPageBytes - 1) / kTouchPageBytes * kTouchPageBytes;
  touch_pages(v.data(), from, count * sizeof(T), threads);
}

// Storage for up to `capacity` elements that a caller writes in full before it reads them (a layer's
// plans): nothing is constructed first, as a vector's resize does on one thread (the fence's wall at
// 6 m is 0.28 million plans, 21 MB written before the planning wrote them all again). T is an
// aggregate, trivially copyable and destructible: an implicit-lifetime type, whose objects the
// allocation itself creates. The used part's pages are faulted in by the threads as it grows.
template <class T>
class WriteFirstArray {
  static_assert(std::is_aggregate_v<T> && std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  explicit WriteFirstArray(std::size_t capacity) : capacity_(capacity), data_(capacity > 0 ? HugePageAllocator<T>().allocate(capacity) : nullptr) {}
  ~WriteFirstArray() {
    if (data_) HugePageAllocator<T>().deallocate(data_, capacity_);
  }
  WriteFirstArray(const WriteFirstArray&) = delete;
  WriteFirstArray& operator=(const WriteFirstArray&) = delete;

  // The first `count` elements (at most the capacity), for the caller to write before it reads them.
  std::span<T> first(std::size_t count, int threads) {
    if (count > capacity_) throw std::length_error("WriteFirstArray: " + std::to_string(count) + " elements of " + std::to_string(capacity_));
    faulted_bytes_ = touch_pages(data_, faulted_bytes_, count * sizeof(T), threads);
    return {data_, count};
  }

 private:
  std::size_t capacity_;
  T* data_;
  std::size_t faulted_bytes_ = 0;  // a whole number of pages from the start
};

}  // namespace lensmith::render_detail

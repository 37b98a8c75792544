// Fresh memory faulted in from several threads at once. The kernel zeroes a page in the thread that
// first writes to it, and on a virtual machine that is the dearest part of touching fresh memory:
// the host backs the page too (docs/performance.md measured 0.05 to 2.4 ms a MiB on its KVM guest,
// from hour to hour). A frame-sized buffer filled by one thread (a vector resized, a layer's sources
// copied) paid all of it on that thread.
#pragma once

#include <omp.h>

#include <cstddef>

#include "lensmith/core/huge_page_allocator.h"

namespace lensmith::render_detail {

// Makes room in `v` for `count` elements and faults in the pages of that room beyond its elements
// (the storage no element lives in yet) from `threads` threads, a contiguous share each.
template <class T>
void fault_in(LargeVector<T>& v, std::size_t count, int threads) {
  if (count > v.capacity()) v.reserve(count);
  constexpr std::size_t kPageBytes = 4096;
  volatile unsigned char* const storage = reinterpret_cast<unsigned char*>(v.data());
  const std::size_t from = (v.size() * sizeof(T) + kPageBytes - 1) / kPageBytes * kPageBytes, to = count * sizeof(T);
  if (to <= from) return;
  const auto pages = static_cast<std::ptrdiff_t>((to - from + kPageBytes - 1) / kPageBytes);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t k = 0; k < pages; ++k) storage[from + static_cast<std::size_t>(k) * kPageBytes] = 0;
}

}  // namespace lensmith::render_detail

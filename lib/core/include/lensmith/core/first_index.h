// The first index at which a test holds, found by several threads: the checks of a whole picture
// (a value that is not radiance, a NaN to be written, an invalid depth) look at every pixel, and
// what they look for is rare, so each thread scans its contiguous share to the end and the least
// index found wins: the same answer, and the same error message, as a scan in order.
#pragma once

#include <algorithm>
#include <cstddef>

namespace lensmith {

// The first k in [0, n) with found(k), or n; on `threads` OpenMP threads (1: this one) where the
// caller is built with OpenMP.
template <class Found>
std::size_t first_index_where(std::size_t n, int threads, Found found) {
  std::size_t first = n;
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for num_threads(std::max(1, threads)) schedule(static) reduction(min : first)
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    if (found(static_cast<std::size_t>(k))) first = std::min(first, static_cast<std::size_t>(k));
  }
  return first;
}

}  // namespace lensmith

// Halton's low-discrepancy sequence (J. H. Halton, "On the efficiency of certain quasi-random
// sequences of points in evaluating multi-dimensional integrals", Numer. Math. 2, 1960): the
// radical inverse of i in a prime base, for the renderers' lens samples.
#pragma once

#include <cstdint>

namespace lensmith {

// The digits of i in `base` mirrored about the radix point: in [0, 1).
inline double radical_inverse(std::uint64_t i, std::uint64_t base) {
  const double inv = 1.0 / static_cast<double>(base);
  double f = inv, r = 0.0;
  while (i > 0) {
    r += f * static_cast<double>(i % base);
    i /= base;
    f *= inv;
  }
  return r;
}

}  // namespace lensmith

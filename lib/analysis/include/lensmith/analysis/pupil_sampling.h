// Ray patterns on the normalised entrance pupil (the unit disc): Zemax's hexapolar rings (a centre
// ray and ring k of 6k rays, the first on the +x pupil axis; N rings give 1 + 3 N (N + 1) rays:
// OpticStudio User Guide, "Hexapolar Rings") and seeded uniform random points (reproducible on
// every platform: SplitMix64 plus the inverse-CDF disc map r = sqrt(u), phi = 2 pi v).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "lensmith/trace/ray_aiming.h"

namespace lensmith {

struct PupilSampling {
  enum class Kind { Hexapolar, Random };
  Kind kind = Kind::Hexapolar;
  int rings = 6;              // Hexapolar: number of rings, 1 to 200 (6 rings = 127 rays, as Zemax's default)
  int random_rays = 500;      // Random: number of rays, 1 to 1000000
  std::uint64_t seed = 1;     // Random: the same seed gives the same points everywhere

  void validate() const;      // throws OptionsError naming the field
  // The pupil points, in a fixed order: centre first, then ring by ring counter-clockwise from +x.
  std::vector<PupilCoordinate> samples() const;
  std::size_t count() const;
  // 1 + 3 N (N + 1): the centre ray plus rings of 6, 12, ..., 6 N rays.
  static std::size_t hexapolar_count(int rings);
  std::string to_string() const;  // "hexapolar, 6 rings (127 rays)" / "random, 500 rays, seed 1"
};

}  // namespace lensmith

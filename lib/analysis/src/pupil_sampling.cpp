// Hexapolar and seeded random patterns on the unit pupil (OpticStudio User Guide, "Hexapolar Rings").
#include "lensmith/analysis/pupil_sampling.h"

#include "lensmith/core/split_mix.h"
#include <cmath>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

}  // namespace

void PupilSampling::validate() const {
  if (kind == Kind::Hexapolar && (rings < 1 || rings > 200)) {
    throw OptionsError("PupilSampling::rings = " + std::to_string(rings) + ": must be 1 to 200");
  }
  if (kind == Kind::Random && (random_rays < 1 || random_rays > 1000000)) {
    throw OptionsError("PupilSampling::random_rays = " + std::to_string(random_rays) + ": must be 1 to 1000000");
  }
}

std::size_t PupilSampling::hexapolar_count(int rings) {
  const auto n = static_cast<std::size_t>(rings);
  return 1 + 3 * n * (n + 1);
}

std::size_t PupilSampling::count() const {
  return kind == Kind::Hexapolar ? hexapolar_count(rings) : static_cast<std::size_t>(random_rays);
}

std::vector<PupilCoordinate> PupilSampling::samples() const {
  validate();
  std::vector<PupilCoordinate> points;
  points.reserve(count());
  if (kind == Kind::Hexapolar) {
    points.push_back({0.0, 0.0});
    for (int ring = 1; ring <= rings; ++ring) {
      // Rings equally spaced in radius; ring k holds 6k rays, the first on the +x axis.
      const double radius = static_cast<double>(ring) / rings;
      const int rays = 6 * ring;
      for (int j = 0; j < rays; ++j) {
        const double phi = 2.0 * kPi * j / rays;
        points.push_back({radius * std::cos(phi), radius * std::sin(phi)});
      }
    }
    return points;
  }
  SplitMix64 rng{seed};
  for (int i = 0; i < random_rays; ++i) {
    const double r = std::sqrt(rng.uniform());
    const double phi = 2.0 * kPi * rng.uniform();
    points.push_back({r * std::cos(phi), r * std::sin(phi)});
  }
  return points;
}

std::string PupilSampling::to_string() const {
  if (kind == Kind::Hexapolar) {
    return "hexapolar, " + std::to_string(rings) + " rings (" + std::to_string(count()) + " rays)";
  }
  return "random, " + std::to_string(random_rays) + " rays, seed " + std::to_string(seed);
}

}  // namespace lensmith

// The calibrated spectrum -> Rec.709 quadrature: every RGB, grey in particular, survives
// RGB -> spectrum -> RGB exactly (to rounding), and the Monte-Carlo samples average to it.
#include "lensmith/color/spectral_quadrature.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>

#include "lensmith/color/spectral_accumulator.h"
#include "lensmith/core/errors.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// The round trip is K A c with K = A^-1 computed in double: rounding only (observed ~1e-16).
constexpr double kRoundTrip = 1e-12;

SpectralQuadrature make_quadrature(int sample_count) {
  SpectralQuadratureOptions o;
  o.sample_count = sample_count;
  return SpectralQuadrature(o);
}

// SplitMix64 in [0, 1): the same random colours on every platform.
struct SplitMix64 {
  std::uint64_t state;
  double uniform() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  }
};
}  // namespace

TEST_CASE("spectral quadrature: N midpoint nodes over 380-780 nm with weights summing to the range", "[color][quadrature]") {
  const SpectralQuadrature q;  // the default: 64 nodes
  REQUIRE(q.size() == 64);
  CHECK_THAT(q.wavelengths_nm().front(), WithinAbs(380.0 + 3.125, 1e-12));  // half of 400 / 64
  CHECK_THAT(q.wavelengths_nm().back(), WithinAbs(780.0 - 3.125, 1e-12));
  double total_nm = 0.0;
  for (double w : q.weights_nm()) total_nm += w;
  CHECK_THAT(total_nm, WithinAbs(400.0, 1e-12));
}

TEST_CASE("spectral quadrature: grey (0.18, 0.18, 0.18) round-trips exactly for N = 3, 16 and 64", "[color][quadrature]") {
  for (int n : {3, 16, 64}) {
    const SpectralQuadrature q = make_quadrature(n);
    const Rgb out = q.round_trip(Rgb{0.18, 0.18, 0.18});
    INFO("N = " << n << ": " << out);
    CHECK_THAT(out.r, WithinAbs(0.18, kRoundTrip));
    CHECK_THAT(out.g, WithinAbs(0.18, kRoundTrip));
    CHECK_THAT(out.b, WithinAbs(0.18, kRoundTrip));
  }
}

TEST_CASE("spectral quadrature: a flat spectrum integrates to the neutral grey of its value", "[color][quadrature]") {
  // The renderer's in-focus grey pixel: each node carries the same value, whatever the basis.
  const SpectralQuadrature q;
  const Rgb out = q.integrate(std::vector<double>(q.size(), 0.5));
  INFO(out);
  CHECK_THAT(out.r, WithinAbs(0.5, kRoundTrip));
  CHECK_THAT(out.g, WithinAbs(0.5, kRoundTrip));
  CHECK_THAT(out.b, WithinAbs(0.5, kRoundTrip));
}

TEST_CASE("spectral quadrature: 200 random RGBs in [0, 2] round-trip for N = 3, 16 and 64", "[color][quadrature]") {
  SplitMix64 rng{42};
  for (int n : {3, 16, 64}) {
    const SpectralQuadrature q = make_quadrature(n);
    for (int k = 0; k < 200; ++k) {
      const Rgb in{2.0 * rng.uniform(), 2.0 * rng.uniform(), 2.0 * rng.uniform()};
      const Rgb out = q.round_trip(in);
      INFO("N = " << n << ": " << in << " -> " << out);
      CHECK_THAT(out.r, WithinAbs(in.r, kRoundTrip));
      CHECK_THAT(out.g, WithinAbs(in.g, kRoundTrip));
      CHECK_THAT(out.b, WithinAbs(in.b, kRoundTrip));
    }
  }
}

TEST_CASE("spectral quadrature: light only near 550 nm maps to a green RGB", "[color][quadrature]") {
  // All the light at the node nearest 550 nm (551.875 nm for N = 64).
  const SpectralQuadrature q;
  std::vector<double> spectrum(q.size(), 0.0);
  std::size_t nearest = 0;
  for (std::size_t i = 1; i < q.size(); ++i) {
    if (std::abs(q.wavelengths_nm()[i] - 550.0) < std::abs(q.wavelengths_nm()[nearest] - 550.0)) nearest = i;
  }
  spectrum[nearest] = 1.0;
  const Rgb out = q.integrate(spectrum);
  INFO("node " << nearest << " at " << q.wavelengths_nm()[nearest] << " nm -> " << out);
  CHECK(out.g > 0.0);
  CHECK(out.g > 4.0 * std::abs(out.r));
  CHECK(out.g > 4.0 * std::abs(out.b));
}

TEST_CASE("spectral quadrature: the Monte-Carlo mean over all N strata equals the quadrature", "[color][quadrature][montecarlo]") {
  const SpectralQuadrature q;
  const Rgb colour{0.7, 0.2, 0.05};
  SpectralAccumulator acc;
  for (std::size_t i = 0; i < q.size(); ++i) {
    // Stratum i by its jittered u, as a renderer would draw it.
    const WavelengthSample s = q.sample((static_cast<double>(i) + 0.37) / static_cast<double>(q.size()));
    REQUIRE(s.index == i);
    CHECK_THAT(s.probability, WithinAbs(1.0 / 64.0, 1e-18));
    acc.add(s, q.basis().spectrum_value(colour, s.wavelength_nm));
  }
  const Rgb mean = acc.mean();
  INFO(acc);
  CHECK(acc.count() == q.size());
  CHECK_THAT(mean.r, WithinAbs(colour.r, kRoundTrip));
  CHECK_THAT(mean.g, WithinAbs(colour.g, kRoundTrip));
  CHECK_THAT(mean.b, WithinAbs(colour.b, kRoundTrip));
}

TEST_CASE("spectral quadrature: u below 0 or from 1 up is clamped to the first or last node", "[color][quadrature][montecarlo]") {
  const SpectralQuadrature q = make_quadrature(16);
  CHECK(q.sample(-0.25).index == 0);
  CHECK(q.sample(1.0).index == 15);
  CHECK(q.sample(0.999999).index == 15);
  CHECK_THROWS_AS(q.sample_at(16), std::out_of_range);
}

TEST_CASE("spectral quadrature options: each bad field is named with its constraint", "[color][quadrature]") {
  SpectralQuadratureOptions o;
  o.sample_count = 2;
  CHECK_THROWS_WITH(SpectralQuadrature(o), Catch::Contains("sample_count = 2") && Catch::Contains("must be 3"));
  o = {};
  o.max_wavelength_nm = 300.0;
  CHECK_THROWS_AS(SpectralQuadrature(o), OptionsError);
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("max_wavelength_nm = 300"));
  o = {};
  CHECK_THROWS_AS(SpectralQuadrature(o).integrate(std::vector<double>(3, 1.0)), ComputationError);
}

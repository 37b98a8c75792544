// Pupil ray patterns: Zemax's hexapolar rule (OpticStudio User Guide, "Hexapolar Rings": ring k
// holds 6k rays, the first at 0 degrees on the pupil's x axis; 5 rings = 1 + 6 + 12 + 18 + 24 + 30
// = 91 rays) and seeded uniform random points in the unit disc.
#include "lensmith/analysis/pupil_sampling.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "lensmith/core/errors.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

namespace {
// Positions are cos/sin of exact multiples of 2 pi / 6k: a few ulps.
constexpr double kTrig = 1e-14;
}  // namespace

TEST_CASE("hexapolar sampling: N rings give 1 + 3 N (N + 1) rays, as OpticStudio's 5 rings = 91 and 6 rings = 127", "[analysis][sampling]") {
  CHECK(PupilSampling::hexapolar_count(1) == 7);
  CHECK(PupilSampling::hexapolar_count(5) == 91);   // the User Guide's worked example
  CHECK(PupilSampling::hexapolar_count(6) == 127);  // the Standard Spot default
  for (int rings : {1, 2, 5, 6, 17}) {
    PupilSampling s;
    s.rings = rings;
    INFO("rings " << rings);
    CHECK(s.samples().size() == PupilSampling::hexapolar_count(rings));
    CHECK(s.count() == s.samples().size());
  }
}

TEST_CASE("hexapolar sampling: ring k has 6k rays at radius k/N, the first on the +x axis", "[analysis][sampling]") {
  PupilSampling s;
  s.rings = 4;
  const auto points = s.samples();
  REQUIRE(points.size() == 61);
  CHECK(points[0].px == 0.0);
  CHECK(points[0].py == 0.0);
  std::size_t index = 1;
  for (int ring = 1; ring <= 4; ++ring) {
    INFO("ring " << ring);
    // First ray of the ring on +x.
    CHECK_THAT(points[index].px, WithinAbs(ring / 4.0, kTrig));
    CHECK_THAT(points[index].py, WithinAbs(0.0, kTrig));
    for (int j = 0; j < 6 * ring; ++j, ++index) CHECK_THAT(std::hypot(points[index].px, points[index].py), WithinAbs(ring / 4.0, kTrig));
  }
  CHECK(index == points.size());
}

TEST_CASE("random sampling: the same seed gives the same points, another seed others, all uniform in the unit disc", "[analysis][sampling]") {
  PupilSampling a;
  a.kind = PupilSampling::Kind::Random;
  a.random_rays = 20000;
  a.seed = 7;
  PupilSampling b = a;
  PupilSampling c = a;
  c.seed = 8;
  const auto pa = a.samples(), pb = b.samples(), pc = c.samples();
  REQUIRE(pa.size() == 20000);
  CHECK(pa[123].px == pb[123].px);
  CHECK(pa[19999].py == pb[19999].py);
  CHECK(pa[0].px != pc[0].px);
  double mean_r2 = 0.0, mean_x = 0.0, mean_y = 0.0;
  for (const auto& p : pa) {
    const double r2 = p.px * p.px + p.py * p.py;
    CHECK(r2 <= 1.0);
    mean_r2 += r2;
    mean_x += p.px;
    mean_y += p.py;
  }
  mean_r2 /= static_cast<double>(pa.size());
  mean_x /= static_cast<double>(pa.size());
  mean_y /= static_cast<double>(pa.size());
  // Uniform in the disc: r^2 is uniform on [0, 1], mean 1/2, standard deviation 1/sqrt(12); with
  // 20000 points the standard error is 0.002, so 0.01 is five standard errors (r uniform would give 1/3).
  constexpr double kFiveStandardErrors = 0.01;
  CHECK_THAT(mean_r2, WithinAbs(0.5, kFiveStandardErrors));
  // The mean of x has standard deviation 0.5 / sqrt(20000) = 0.0035: five of them.
  CHECK_THAT(mean_x, WithinAbs(0.0, 0.018));
  CHECK_THAT(mean_y, WithinAbs(0.0, 0.018));
}

TEST_CASE("pupil sampling options name the field and the limit", "[analysis][sampling]") {
  PupilSampling s;
  s.rings = 0;
  CHECK_THROWS_WITH(s.validate(), Catch::Contains("PupilSampling::rings = 0") && Catch::Contains("1 to 200"));
  s.kind = PupilSampling::Kind::Random;
  s.random_rays = 0;
  CHECK_THROWS_AS(s.samples(), OptionsError);
}

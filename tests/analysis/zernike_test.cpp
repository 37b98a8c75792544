// Zernike polynomials against their definitions: Noll's table of the first terms (J. Opt. Soc. Am. 66, 207,
// 1976, Table I), the Fringe set's textbook forms (Malacara, Optical Shop Testing, 3rd ed., Table 13.2),
// orthonormality of the Standard terms over the unit disc (a physics identity, integrated numerically), and
// a fit that recovers known coefficients.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "lensmith/analysis/zernike.h"
#include "lensmith/core/errors.h"

using namespace lensmith;
using Catch::Matchers::WithinAbs;

TEST_CASE("Zernike terms are numbered as Noll's Standard and the University of Arizona's Fringe sets number them", "[analysis][zernike]") {
  // Noll, Table I: Z1 (0,0), Z2 (1,1) cos, Z3 (1,1) sin, Z4 (2,0), Z5 (2,2) sin, Z6 (2,2) cos, Z7 (3,1) sin,
  // Z8 (3,1) cos, Z9 (3,3) sin, Z10 (3,3) cos, Z11 (4,0).
  const std::vector<ZernikeTerm> noll{{0, 0}, {1, 1}, {1, -1}, {2, 0}, {2, -2}, {2, 2}, {3, -1}, {3, 1}, {3, -3}, {3, 3}, {4, 0}};
  for (std::size_t j = 0; j < noll.size(); ++j) CHECK(zernike_term(ZernikeOrdering::Standard, static_cast<int>(j) + 1) == noll[j]);
  CHECK(zernike_term(ZernikeOrdering::Standard, 22) == ZernikeTerm{6, 0});  // primary spherical's next order
  // Fringe: Z4 defocus, Z5/Z6 astigmatism, Z7/Z8 coma, Z9 spherical, Z16 (6,0), Z25 (8,0), Z36 (10,0), Z37 (12,0).
  CHECK(zernike_term(ZernikeOrdering::Fringe, 4) == ZernikeTerm{2, 0});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 5) == ZernikeTerm{2, 2});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 8) == ZernikeTerm{3, -1});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 9) == ZernikeTerm{4, 0});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 10) == ZernikeTerm{3, 3});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 16) == ZernikeTerm{6, 0});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 25) == ZernikeTerm{8, 0});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 36) == ZernikeTerm{10, 0});
  CHECK(zernike_term(ZernikeOrdering::Fringe, 37) == ZernikeTerm{12, 0});
  CHECK_THROWS_AS(zernike_term(ZernikeOrdering::Fringe, 38), OptionsError);
  CHECK_THROWS_AS(zernike_term(ZernikeOrdering::Standard, 0), OptionsError);
}

TEST_CASE("Fringe terms have their textbook forms and Standard terms are normalised", "[analysis][zernike]") {
  constexpr double kRounding = 1e-12;
  for (double rho : {0.0, 0.3, 0.77, 1.0}) {
    for (double theta : {0.0, 0.4, 2.2}) {
      const double r2 = rho * rho;
      CHECK_THAT(zernike_value(ZernikeOrdering::Fringe, 4, rho, theta), WithinAbs(2 * r2 - 1, kRounding));
      CHECK_THAT(zernike_value(ZernikeOrdering::Fringe, 7, rho, theta), WithinAbs((3 * r2 * rho - 2 * rho) * std::cos(theta), kRounding));
      CHECK_THAT(zernike_value(ZernikeOrdering::Fringe, 9, rho, theta), WithinAbs(6 * r2 * r2 - 6 * r2 + 1, kRounding));
      CHECK_THAT(zernike_value(ZernikeOrdering::Fringe, 12, rho, theta), WithinAbs((4 * r2 * r2 - 3 * r2) * std::cos(2 * theta), kRounding));
      CHECK_THAT(zernike_value(ZernikeOrdering::Fringe, 16, rho, theta),
                 WithinAbs(20 * r2 * r2 * r2 - 30 * r2 * r2 + 12 * r2 - 1, kRounding));
      CHECK_THAT(zernike_value(ZernikeOrdering::Standard, 11, rho, theta), WithinAbs(std::sqrt(5.0) * (6 * r2 * r2 - 6 * r2 + 1), kRounding));
      CHECK_THAT(zernike_value(ZernikeOrdering::Standard, 5, rho, theta), WithinAbs(std::sqrt(6.0) * r2 * std::sin(2 * theta), kRounding));
    }
  }
}

TEST_CASE("Standard Zernike terms are orthonormal over the unit disc", "[analysis][zernike]") {
  // Midpoint rule in rho and theta (exact in theta for these frequencies; in rho its error is O(1 / N^2):
  // 2e-5 at N = 400 for the degrees below, so 1e-4).
  constexpr int kRings = 400, kSectors = 64;
  constexpr double kQuadrature = 1e-4;
  const int terms = 15;
  std::vector<double> gram(terms * terms, 0.0);
  for (int i = 0; i < kRings; ++i) {
    const double rho = (i + 0.5) / kRings;
    for (int k = 0; k < kSectors; ++k) {
      const double theta = 2.0 * M_PI * (k + 0.5) / kSectors;
      const double weight = rho / kRings * (2.0 * M_PI / kSectors) / M_PI;  // dA / (pi): the disc's mean
      std::vector<double> z(terms);
      for (int j = 0; j < terms; ++j) z[j] = zernike_value(ZernikeOrdering::Standard, j + 1, rho, theta);
      for (int a = 0; a < terms; ++a) {
        for (int b = 0; b < terms; ++b) gram[a * terms + b] += weight * z[a] * z[b];
      }
    }
  }
  for (int a = 0; a < terms; ++a) {
    for (int b = 0; b < terms; ++b) {
      INFO("Z" << a + 1 << " . Z" << b + 1);
      CHECK_THAT(gram[a * terms + b], WithinAbs(a == b ? 1.0 : 0.0, kQuadrature));
    }
  }
}

TEST_CASE("A Zernike fit recovers the coefficients a wavefront was made of, and says when the samples cannot", "[analysis][zernike]") {
  std::vector<double> xs, ys, ws;
  for (int i = -10; i <= 10; ++i) {
    for (int k = -10; k <= 10; ++k) {
      const double x = i / 10.0, y = k / 10.0;
      if (x * x + y * y > 1.0) continue;
      const double rho = std::hypot(x, y), theta = std::atan2(y, x);
      xs.push_back(x);
      ys.push_back(y);
      ws.push_back(0.25 * zernike_value(ZernikeOrdering::Fringe, 4, rho, theta) - 0.1 * zernike_value(ZernikeOrdering::Fringe, 8, rho, theta) +
                   0.05 * zernike_value(ZernikeOrdering::Fringe, 9, rho, theta));
    }
  }
  const std::vector<double> c = fit_zernike(ZernikeOrdering::Fringe, 16, xs, ys, ws);
  constexpr double kRounding = 1e-12;
  for (int j = 1; j <= 16; ++j) {
    const double expected = j == 4 ? 0.25 : j == 8 ? -0.1 : j == 9 ? 0.05 : 0.0;
    CHECK_THAT(c[static_cast<std::size_t>(j - 1)], WithinAbs(expected, kRounding));
  }
  // Three samples cannot determine sixteen terms.
  CHECK_THROWS_AS(fit_zernike(ZernikeOrdering::Fringe, 16, std::vector<double>{0.0, 0.5, 0.1}, std::vector<double>{0.0, 0.0, 0.3},
                              std::vector<double>{1.0, 2.0, 3.0}),
                  ComputationError);
}

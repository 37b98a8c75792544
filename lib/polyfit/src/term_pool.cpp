// Term pools: all monomials up to a degree, and the parity-filtered pools of a rotationally
// symmetric lens (rules and their justification in term_pool.h).
#include "lensmith/polyfit/term_pool.h"

#include <string>

namespace lensmith {

std::ostream& operator<<(std::ostream& os, OutputParity parity) {
  switch (parity) {
    case OutputParity::kOddInX: return os << "odd in x";
    case OutputParity::kOddInY: return os << "odd in y";
    case OutputParity::kEven: return os << "even";
  }
  return os << "unknown parity";
}

std::vector<Monomial> all_monomials(int max_degree) {
  if (max_degree < 0 || max_degree > kMaxPolyDegree) {
    throw OptionsError("all_monomials: max_degree = " + std::to_string(max_degree) + ": must be in 0.." +
                       std::to_string(kMaxPolyDegree));
  }
  std::vector<Monomial> pool;
  for (int degree = 0; degree <= max_degree; ++degree) {
    // Exponents of total `degree`, in descending lexicographic order (x^d first, lambda^d last).
    for (int a = degree; a >= 0; --a) {
      for (int b = degree - a; b >= 0; --b) {
        for (int c = degree - a - b; c >= 0; --c) {
          for (int d = degree - a - b - c; d >= 0; --d) {
            const int e = degree - a - b - c - d;
            Monomial m;
            m.exponents = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b), static_cast<std::uint8_t>(c),
                           static_cast<std::uint8_t>(d), static_cast<std::uint8_t>(e)};
            pool.push_back(m);
          }
        }
      }
    }
  }
  return pool;
}

bool allowed_by_symmetry(const Monomial& m, OutputParity parity) {
  const bool odd_x = (m.exponents[0] + m.exponents[2]) % 2 == 1;  // sign under x -> -x
  const bool odd_y = (m.exponents[1] + m.exponents[3]) % 2 == 1;  // sign under y -> -y
  switch (parity) {
    case OutputParity::kOddInX: return odd_x && !odd_y;
    case OutputParity::kOddInY: return !odd_x && odd_y;
    case OutputParity::kEven: return !odd_x && !odd_y;
  }
  return false;
}

std::vector<Monomial> symmetric_monomials(int max_degree, OutputParity parity) {
  std::vector<Monomial> pool;
  for (const Monomial& m : all_monomials(max_degree)) {
    if (allowed_by_symmetry(m, parity)) pool.push_back(m);
  }
  return pool;
}

}  // namespace lensmith

// The shipped lenses: each loads, validates and carries its source.
#include <catch2/catch.hpp>

#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_library.h"
#include "reference_lenses.h"

using namespace lensmith;

TEST_CASE("shipped lenses: at least ten, each loads and names its source", "[prescription][library]") {
  const auto lenses = LensLibrary::list();
  CHECK(lenses.size() >= 10);
  for (const auto& l : lenses) {
    INFO("lens " << l.id);
    CHECK_FALSE(l.name.empty());
    CHECK_FALSE(l.source.empty());
    CHECK_NOTHROW(LensLibrary::load(l.id));
  }
}

TEST_CASE("shipped lenses: an unknown name lists the closest shipped names", "[prescription][library]") {
  CHECK_THROWS_WITH(LensLibrary::load("sasian-triplett"), Catch::Contains("closest shipped lenses: sasian-triplet"));
}

namespace {

// The shipped file and the book's table describe the same optics (names and notes aside).
void check_same_optics(const Prescription& shipped, const Prescription& book) {
  REQUIRE(shipped.surfaces.size() == book.surfaces.size());
  constexpr double kTyped = 1e-12;  // the numbers were typed from the same table
  for (std::size_t i = 0; i < book.surfaces.size(); ++i) {
    INFO("surface " << i + 1);
    const Surface& a = shipped.surfaces[i];
    const Surface& b = book.surfaces[i];
    CHECK_THAT(a.curvature_per_mm, Catch::Matchers::WithinAbs(b.curvature_per_mm, kTyped));
    CHECK_THAT(a.thickness_mm, Catch::Matchers::WithinAbs(b.thickness_mm, kTyped));
    CHECK(a.is_stop == b.is_stop);
    CHECK(a.semi_diameter_mm == b.semi_diameter_mm);
    for (double wavelength_nm : {450.0, 587.5618, 650.0}) {
      CHECK_THAT(a.medium.index(wavelength_nm), Catch::Matchers::WithinAbs(b.medium.index(wavelength_nm), kTyped));
    }
  }
  CHECK(shipped.aperture == book.aperture);
}

}  // namespace

TEST_CASE("shipped lenses: smith-cooke-triplet is Smith's printed prescription", "[prescription][library]") {
  check_same_optics(LensLibrary::load("smith-cooke-triplet").prescription, testing::smith_cooke_triplet());
}

TEST_CASE("shipped lenses: sasian-triplet is the prescription in ray-optics' documentation", "[prescription][library]") {
  check_same_optics(LensLibrary::load("sasian-triplet").prescription, testing::sasian_triplet());
}

// The shipped lenses: each loads, validates and carries its source.
#include <catch2/catch.hpp>

#include "lensmith/core/errors.h"
#include "lensmith/prescription/lens_library.h"

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

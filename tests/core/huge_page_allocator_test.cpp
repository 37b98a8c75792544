// HugePageAllocator (lensmith/core/huge_page_allocator.h): frame-sized blocks on 2 MiB boundaries
// (what transparent huge pages need), small ones from operator new, contents kept as a vector grows.
#include <catch2/catch.hpp>

#include <cstdint>
#include <numeric>

#include "lensmith/core/huge_page_allocator.h"

using namespace lensmith;

TEST_CASE("A large vector's block starts on a 2 MiB boundary and keeps its contents as it grows", "[core]") {
  constexpr std::size_t kHuge = HugePageAllocator<double>::kHugePageBytes;
  LargeVector<double> v(kHuge / sizeof(double) + 1);  // just over one huge page
  CHECK(reinterpret_cast<std::uintptr_t>(v.data()) % kHuge == 0);
  std::iota(v.begin(), v.end(), 0.0);
  v.resize(3 * v.size());  // reallocates: the old values must move with it
  CHECK(reinterpret_cast<std::uintptr_t>(v.data()) % kHuge == 0);
  CHECK(v[kHuge / sizeof(double)] == static_cast<double>(kHuge / sizeof(double)));
  CHECK(v.back() == 0.0);
}

TEST_CASE("A small vector through the allocator is an ordinary aligned block", "[core]") {
  LargeVector<std::int32_t> small(100, 7);
  CHECK(reinterpret_cast<std::uintptr_t>(small.data()) % alignof(std::int32_t) == 0);
  CHECK(small[99] == 7);
  LargeVector<std::int32_t> copy = small;  // the allocators compare equal: copies and moves work
  CHECK(copy == small);
}

// HugePageAllocator (lensmith/core/huge_page_allocator.h): blocks from 512 KiB up on 2 MiB
// boundaries (what transparent huge pages need), small ones from operator new, contents kept as a
// vector grows.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstdlib>
#include <numeric>

#include "lensmith/core/huge_page_allocator.h"

using namespace lensmith;

TEST_CASE("A large vector's block starts on a 2 MiB boundary and keeps its contents as it grows", "[core]") {
  constexpr std::size_t kHuge = kHugePageBytes;
  LargeVector<double> v(kHuge / sizeof(double) + 1);  // just over one huge page
  CHECK(reinterpret_cast<std::uintptr_t>(v.data()) % kHuge == 0);
  std::iota(v.begin(), v.end(), 0.0);
  v.resize(3 * v.size());  // reallocates: the old values must move with it
  CHECK(reinterpret_cast<std::uintptr_t>(v.data()) % kHuge == 0);
  CHECK(v[kHuge / sizeof(double)] == static_cast<double>(kHuge / sizeof(double)));
  CHECK(v.back() == 0.0);
}

TEST_CASE("A block from 512 KiB up starts on a 2 MiB boundary too", "[core]") {
  LargeVector<char> medium(kHugePageFromBytes);
  CHECK(reinterpret_cast<std::uintptr_t>(medium.data()) % kHugePageBytes == 0);
  medium.back() = 1;  // the whole block is usable
  CHECK(medium.back() == 1);
  void* p = allocate_huge_pages(kHugePageFromBytes + 1);
  CHECK(reinterpret_cast<std::uintptr_t>(p) % kHugePageBytes == 0);
  std::free(p);
}

TEST_CASE("A small vector through the allocator is an ordinary aligned block", "[core]") {
  LargeVector<std::int32_t> small(100, 7);
  CHECK(reinterpret_cast<std::uintptr_t>(small.data()) % alignof(std::int32_t) == 0);
  CHECK(small[99] == 7);
  LargeVector<std::int32_t> copy = small;  // the allocators compare equal: copies and moves work
  CHECK(copy == small);
}

// The command line's global operator new and delete: blocks of 2 MiB and more come as whole,
// 2-MiB aligned pages advised to the kernel as transparent huge pages (allocate_huge_pages, what
// HugePageAllocator gives the renderer's own frame-sized buffers), so that the rest (pictures and
// depth maps as read, the EXR codec's buffers, the output picture) is faulted in 2 MiB at a time
// as well. On the KVM guests of
// docs/performance.md a first touch costs about 12 us per 4 KiB page (3 ms per MiB): the 600 x 400
// street scene's whole `lensmith bokeh` process spent about 25 ms of its 0.22 s on such faults.
// Smaller blocks are plain malloc; every block is released by free (aligned_alloc's blocks are
// free's too), so the sized, unsized and array forms need no record of which path made a block.
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

#include "lensmith/core/huge_page_allocator.h"

namespace {

// glibc maps blocks from its mmap threshold up on their own and, each time such a block is freed,
// raises the threshold to its size (up to 32 MiB): from then on large blocks come from the heap,
// where their 2 MiB ranges share page tables with small blocks already faulted in as 4 KiB pages, and
// the kernel faults them in 4 KiB at a time whatever the advice. A threshold set by mallopt stays
// where it is: at kHugePageFromBytes a huge-page block the heap's top cannot hold gets a mapping of
// its own (one it can hold lies in the heap's huge pages below). The heap is kept up to
// kTrimThresholdBytes when freed (the default trims it from 128 KiB), so that freed blocks are
// reused, not returned and faulted in again: more than kHeapReserveBytes, or the reserve's own probe,
// freed, would trim it before it is advised. Street scene (docs/performance.md): 3700 -> 1600 page
// faults a process; reading 20 -> 12 ms, layering 10 -> 6 ms. Whoever sets glibc's malloc tunables
// (GLIBC_TUNABLES, MALLOC_*_ environment variables) keeps them.
constexpr int kTrimThresholdBytes = 128 << 20;
// The small blocks themselves (the codecs' line buffers, the command line's and the renderer's
// small vectors) come from the heap, which a process touches 4 KiB at a time: about 500 faults, half
// of the street scene's process. So the heap's first kHeapReserveBytes are reserved at start-up from
// a 2 MiB boundary and advised as huge pages, before malloc writes to them (which glibc's own
// glibc.malloc.hugetlb=1 tunable does, but a tunable is read only from the environment at start-up).
// The break is moved to the boundary first (glibc takes a break someone else moved as the start of
// new heap memory), and the first huge page, which malloc's bookkeeping has touched as small pages
// by the time the advice can be given, is collapsed into a huge one (MADV_COLLAPSE, Linux 6.1;
// ignored where the kernel lacks it). Memory beyond the reserve is faulted in as before. Street
// scene: 1155 -> 640 page faults a process (docs/performance.md). 64 MiB, not 32: with one arena
// (below) a 600 x 400 render's heap outgrew 32 (the fence focused at 6 m: 1090 faults a process at
// 32 MiB, 350 at 64).
constexpr int kHeapReserveBytes = 64 << 20;
// The OpenMP threads' small blocks (the renderer's per-row lists, made in parallel loops) came from
// glibc's arena for each thread, a mapping of its own faulted in 4 KiB at a time: 890 of the fence's
// faults a process. With one arena they come from the heap's huge pages too (their lock is taken by
// blocks too large for the threads' caches only). With the larger reserve, the fence at 6 m: 1250 ->
// 350 faults a process, the objects scene 2200 -> 370; 4 % of the objects scene's process time and
// 8 % of the fence's (medians of 41, alternately). MALLOC_ARENA_MAX, where set, is kept.
constexpr int kArenas = 1;
constexpr int kDefaultTopPadBytes = 128 << 10;  // glibc's M_TOP_PAD
#ifndef MADV_COLLAPSE
constexpr int MADV_COLLAPSE = 25;  // linux/mman.h, Linux 6.1
#endif

void reserve_heap_in_huge_pages() {
  const auto huge = static_cast<std::uintptr_t>(lensmith::kHugePageBytes);
  const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto end_of_heap = [] { return reinterpret_cast<std::uintptr_t>(sbrk(0)); };
  const std::uintptr_t old_end = end_of_heap();
  const std::uintptr_t aligned = (old_end + huge - 1) / huge * huge;
  if (aligned > old_end && sbrk(static_cast<intptr_t>(aligned - old_end)) == reinterpret_cast<void*>(-1)) return;
  const std::uintptr_t begin = end_of_heap();
  // A block the heap's top cannot hold makes malloc extend the heap by it and the top pad.
  mallopt(M_TOP_PAD, kHeapReserveBytes);
  void* volatile probe = std::malloc(std::size_t{256} << 10);
  const std::uintptr_t end = end_of_heap() / page * page;
  std::free(probe);
  mallopt(M_TOP_PAD, kDefaultTopPadBytes);
  if (begin % huge != 0 || end < begin + huge) return;  // the heap did not grow where expected: leave it
  if (madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE) != 0) return;
  madvise(reinterpret_cast<void*>(begin), huge, MADV_COLLAPSE);  // advice only
}

[[gnu::constructor]] void keep_large_blocks_mapped_alone() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if ((tunables != nullptr && std::strstr(tunables, "glibc.malloc.") != nullptr) || std::getenv("MALLOC_MMAP_THRESHOLD_") != nullptr ||
      std::getenv("MALLOC_TRIM_THRESHOLD_") != nullptr || std::getenv("MALLOC_TOP_PAD_") != nullptr) {
    return;
  }
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(lensmith::kHugePageFromBytes));
  mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes);
  if (std::getenv("MALLOC_ARENA_MAX") == nullptr) mallopt(M_ARENA_MAX, kArenas);
  reserve_heap_in_huge_pages();
}

void* allocate(std::size_t bytes) {
  if (bytes >= lensmith::kHugePageFromBytes) return lensmith::allocate_huge_pages(bytes);
  if (void* p = std::malloc(bytes == 0 ? 1 : bytes)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t /*bytes*/) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t /*bytes*/) noexcept { std::free(p); }

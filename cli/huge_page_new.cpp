// The command line's global operator new and delete: blocks of 512 KiB and more come as whole,
// 2-MiB aligned pages advised to the kernel as transparent huge pages (allocate_huge_pages, what
// HugePageAllocator gives the renderer's own frame-sized buffers), so that the rest (pictures and
// depth maps as read, the EXR codec's buffers, the output picture) is faulted in 2 MiB at a time
// as well. On the KVM guests of
// docs/performance.md a first touch costs about 12 us per 4 KiB page (3 ms per MiB): the 600 x 400
// street scene's whole `lensmith bokeh` process spent about 25 ms of its 0.22 s on such faults.
// Smaller blocks are plain malloc; every block is released by free (aligned_alloc's blocks are
// free's too), so the sized, unsized and array forms need no record of which path made a block.
#include <malloc.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>

#include "lensmith/core/huge_page_allocator.h"

namespace {

// glibc maps blocks from its mmap threshold up on their own and, each time such a block is freed,
// raises the threshold to its size (up to 32 MiB): from then on large blocks come from the heap,
// where their 2 MiB ranges share page tables with small blocks already faulted in as 4 KiB pages, and
// the kernel faults them in 4 KiB at a time whatever the advice. A threshold set by mallopt stays
// where it is: at kHugePageFromBytes every huge-page block has a mapping of its own. The heap is
// kept up to 64 MiB when freed (the default trims it from 128 KiB), so that freed small blocks are
// reused, not returned and faulted in again. Street scene (docs/performance.md): 3700 -> 1600 page
// faults a process; reading 20 -> 12 ms, layering 10 -> 6 ms. Whoever sets glibc's malloc tunables
// (GLIBC_TUNABLES, MALLOC_*_ environment variables) keeps them.
constexpr int kTrimThresholdBytes = 64 << 20;
[[gnu::constructor]] void keep_large_blocks_mapped_alone() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if ((tunables != nullptr && std::strstr(tunables, "glibc.malloc.") != nullptr) || std::getenv("MALLOC_MMAP_THRESHOLD_") != nullptr ||
      std::getenv("MALLOC_TRIM_THRESHOLD_") != nullptr) {
    return;
  }
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(lensmith::kHugePageFromBytes));
  mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes);
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

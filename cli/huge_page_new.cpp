// The command line's global operator new and delete: blocks of 512 KiB and more come as whole,
// 2-MiB aligned pages advised to the kernel as transparent huge pages (allocate_huge_pages, what
// HugePageAllocator gives the renderer's own frame-sized buffers), so that the rest (pictures and
// depth maps as read, the EXR codec's buffers, the output picture) is faulted in 2 MiB at a time
// as well. On the KVM guests of
// docs/performance.md a first touch costs about 12 us per 4 KiB page (3 ms per MiB): the 600 x 400
// street scene's whole `lensmith bokeh` process spent about 25 ms of its 0.22 s on such faults.
// Smaller blocks are plain malloc; every block is released by free (aligned_alloc's blocks are
// free's too), so the sized, unsized and array forms need no record of which path made a block.
#include <cstddef>
#include <cstdlib>
#include <new>

#include "lensmith/core/huge_page_allocator.h"

namespace {
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

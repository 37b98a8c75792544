// Push-pull interpolation of scattered samples over a grid (Gortler, Grzeszczuk, Szeliski & Cohen,
// "The Lumigraph", SIGGRAPH 1996, sec. 3.4): the renderer's way of guessing colour and depth where a
// single image does not know them (behind foreground edges, beyond the frame).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "lensmith/core/huge_page_allocator.h"

namespace lensmith::render_detail {

// The coarser levels' memory, kept from call to call (a renderer calls once per depth layer).
template <std::size_t N>
struct PushPullScratch {
  std::vector<LargeVector<std::array<double, N>>> levels;
};

// `cells` holds, per pixel of a w x h grid, N - 1 weighted sums and their weight (slot N - 1; 0 =
// unknown). Pull sums 2 x 2 blocks down to one cell; push gives every unknown cell its parent's
// normalised value. On return every cell holds normalised values and weight 1 (all zero if no cell
// was known). Rows are shared among `threads` threads; the result does not depend on their number.
// Made for N = 2 (a share) and N = 5 (colour and inverse depth).
template <std::size_t N>
void push_pull(int w, int h, LargeVector<std::array<double, N>>& cells, int threads = 1, PushPullScratch<N>* scratch = nullptr);

}  // namespace lensmith::render_detail

// Push-pull interpolation of scattered samples over a grid (Gortler, Grzeszczuk, Szeliski & Cohen,
// "The Lumigraph", SIGGRAPH 1996, sec. 3.4): the renderer's way of guessing colour and depth where a
// single image does not know them (behind foreground edges, beyond the frame).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "lensmith/core/huge_page_allocator.h"

namespace lensmith::render_detail {

// A cell: N - 1 weighted sums and their weight, in float: the push-pull guesses colour and depth
// where the picture does not know them, far coarser than float's 1e-7, and a frame's cells in double
// (40 bytes a pixel for N = 5) were a large part of the memory a render first touches, which is what
// costs on the virtual machines of docs/performance.md.
template <std::size_t N>
using PushPullCell = std::array<float, N>;

// The coarser levels' memory, kept from call to call (a renderer calls once per depth layer).
template <std::size_t N>
struct PushPullScratch {
  std::vector<LargeVector<PushPullCell<N>>> levels;
  // Address space for the levels of grids up to w x h, so that a later call on a larger window
  // reuses the memory an earlier one faulted in instead of copying it to a fresh block (on a virtual
  // machine the first touch of fresh memory is what costs: docs/performance.md).
  void reserve(int w, int h) {
    for (std::size_t l = 0; w > 1 || h > 1; ++l) {
      w = (w + 1) / 2;
      h = (h + 1) / 2;
      if (levels.size() <= l) levels.emplace_back();
      levels[l].reserve(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    }
  }
};

// `cells` holds, per pixel of a w x h grid, N - 1 weighted sums and their weight (slot N - 1; 0 =
// unknown). Pull sums 2 x 2 blocks down to one cell; push gives every unknown cell its parent's
// normalised value. On return every cell holds normalised values and weight 1 (all zero if no cell
// was known). Rows are shared among `threads` threads; the result does not depend on their number.
// Made for N = 2 (a share) and N = 5 (colour and inverse depth). `finish`, when not empty: only
// these cells (y * w + x) are finished on return, each with the value it gets when all are (the
// others keep partial sums): a caller that reads a few cells of a large grid (the hidden-surface
// fill's targets) skips the finest level's push, about half the work.
template <std::size_t N>
void push_pull(int w, int h, LargeVector<PushPullCell<N>>& cells, int threads = 1, PushPullScratch<N>* scratch = nullptr,
               std::span<const std::size_t> finish = {});

// The same for a caller that wants only the cells `finish` (y * w + x, w x h grid) and has no
// finest level to give: `first` holds the grid's level 1, ceil(w / 2) x ceil(h / 2) cells, each the
// sum of its 2 x 2 finest cells (rows first: (2x, 2y), (2x + 1, 2y), (2x, 2y + 1), (2x + 1, 2y + 1)),
// as push_pull's pull makes it; `own[k]`, finish[k]'s own sums. On return own[k] holds what
// push_pull leaves in cells[finish[k]]. A frame-sized finest level costs its memory twice (written,
// then read by the pull); the hidden-surface fill sums its pixels into level 1 directly. `first` is
// the scratch's to keep (push_pull_first_level sizes it).
template <std::size_t N>
void push_pull_targets(int w, int h, PushPullScratch<N>& scratch, std::span<const std::size_t> finish, std::span<PushPullCell<N>> own,
                       int threads = 1);
// The level-1 grid of a w x h grid in `scratch`, sized ceil(w / 2) x ceil(h / 2) (not cleared).
template <std::size_t N>
LargeVector<PushPullCell<N>>& push_pull_first_level(int w, int h, PushPullScratch<N>& scratch);

}  // namespace lensmith::render_detail

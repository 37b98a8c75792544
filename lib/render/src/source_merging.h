// Level of detail for large footprints: the sources of one layer whose footprints go to a coarse
// splat grid (cells of 2 x 2 or 4 x 4 px, FootprintPlan::level) are merged block by block, one
// source per block of cell size, so that the cost of a layer falls with the square of the cell size
// as its blur grows, as in Krivanek et al.'s level-of-detail splatting ("Fast depth of field
// rendering with surface splatting", CGI 2003, sec. 4: a coarser level of the source hierarchy for
// larger circles of confusion). What lensmith does differently: the blocks are the splat grid's own
// cells, so the merge adds one cell's box to a footprint whose edge the grid softens by about two
// cells already; the merged source leaves from the centre of its members' light (a highlight keeps
// its place), with their summed light and coverage and their coverage-weighted inverse depth, and is
// planned through the ray model at that point like any other source.
#pragma once

#include <cstdint>
#include <vector>

#include "footprint.h"
#include "scatter_source.h"

namespace lensmith::render_detail {

// What a block's members add up to.
struct BlockSum {
  std::size_t first = 0;  // index of the first member in the layer
  int members = 0;
  double rgb[3] = {0.0, 0.0, 0.0};
  double coverage = 0.0;
  double inverse_depth = 0.0;  // coverage-weighted sums
  double coc = 0.0;
  double weight = 0.0;  // of the light centre: light (R + G + B), or coverage where there is none
  double x = 0.0;       // weighted sums of the members' centres, px
  double y = 0.0;
};

// Scratch kept from layer to layer, so that a render allocates (and faults in) its memory once.
struct MergeScratch {
  std::vector<std::int32_t> slots;  // block slots of an image (-1 = empty)
  std::vector<BlockSum> blocks;
  std::vector<std::int32_t> block_of;  // per source: its block, or -1
  ScatterSources layer;    // the merged layer before the swap
};

// Merges the sources of `layer` (of an image width x height px) whose blur puts their footprints on
// a coarse grid (grid_level of |coc_px| >= 1) by blocks of 2^level px, light sources and
// coverage-only ones apart; a source alone in its block is kept as it is. The layer is rewritten in
// the order of the blocks' first members (row-major stays row-major), before planning. Sources
// beyond the frame (a margin of `margin` px each side, where the picture continues) are merged on
// the same blocks, counted from the margin's corner.
void merge_coarse_sources(ScatterSources& layer, int width, int height, MergeScratch& scratch, int margin = 0);

}  // namespace lensmith::render_detail

#include "source_merging.h"

#include <algorithm>
#include <cmath>

namespace lensmith::render_detail {

void merge_coarse_sources(ScatterSources& layer, int frame_width, int frame_height, MergeScratch& scratch, int margin) {
  const int width = frame_width + 2 * margin, height = frame_height + 2 * margin;
  // Slots per level (1, 2) and kind (light, coverage only), over blocks of 2^level px.
  const int bw1 = (width + 1) / 2, bh1 = (height + 1) / 2, bw2 = (width + 3) / 4, bh2 = (height + 3) / 4;
  const std::size_t level1 = static_cast<std::size_t>(bw1) * static_cast<std::size_t>(bh1);
  const std::size_t level2 = static_cast<std::size_t>(bw2) * static_cast<std::size_t>(bh2);
  // The grid level of each source's footprint, from its blur at the reference wavelength (its
  // footprint is at least that large unless clear apertures clip it).
  auto level_of = [](const ScatterSource& s) { return grid_level(std::abs(s.coc_px)); };
  bool any = false;
  for (const ScatterSource& s : layer) any = any || level_of(s) > 0;
  if (!any) return;
  scratch.slots.assign(2 * (level1 + level2), -1);
  auto slot_of = [&](const ScatterSource& s, int level) -> std::int32_t& {
    const std::size_t kind = s.coverage_only ? 1 : 0;
    const auto x = static_cast<std::size_t>(s.x + margin), y = static_cast<std::size_t>(s.y + margin);
    if (level == 1) return scratch.slots[kind * level1 + (y / 2) * bw1 + x / 2];
    return scratch.slots[2 * level1 + kind * level2 + (y / 4) * bw2 + x / 4];
  };

  std::vector<BlockSum>& blocks = scratch.blocks;
  std::vector<std::int32_t>& block_of = scratch.block_of;
  blocks.clear();
  block_of.assign(layer.size(), -1);
  for (std::size_t i = 0; i < layer.size(); ++i) {
    const int level = level_of(layer[i]);
    if (level < 1) continue;
    const ScatterSource& s = layer[i];
    std::int32_t& slot = slot_of(s, level);
    if (slot < 0) {
      slot = static_cast<std::int32_t>(blocks.size());
      BlockSum b;
      b.first = i;
      blocks.push_back(b);
    }
    BlockSum& b = blocks[static_cast<std::size_t>(slot)];
    block_of[i] = slot;
    ++b.members;
    const PixelPoint c = source_centre(s);
    const double light = std::max(0.0, static_cast<double>(s.rgb[0]) + s.rgb[1] + s.rgb[2]);
    const double w = s.coverage_only || !(light > 0.0) ? 1e-6 * s.coverage : light;
    for (int k = 0; k < 3; ++k) b.rgb[k] += s.rgb[static_cast<std::size_t>(k)];
    b.coverage += s.coverage;
    b.inverse_depth += s.coverage * s.inverse_depth_per_mm;
    b.coc += s.coverage * s.coc_px;
    b.weight += w;
    b.x += w * c.x;
    b.y += w * c.y;
  }

  // Rewrite the layer: a merged block's source in place of its first member, its others dropped.
  ScatterSources& merged_layer = scratch.layer;
  merged_layer.clear();
  for (std::size_t i = 0; i < layer.size(); ++i) {
    const std::int32_t slot = block_of[i];
    if (slot < 0 || blocks[static_cast<std::size_t>(slot)].members == 1) {
      merged_layer.push_back(layer[i]);
      continue;
    }
    const BlockSum& b = blocks[static_cast<std::size_t>(slot)];
    if (b.first != i) continue;
    ScatterSource s = layer[i];
    for (int k = 0; k < 3; ++k) s.rgb[static_cast<std::size_t>(k)] = static_cast<float>(b.rgb[k]);
    s.coverage = static_cast<float>(b.coverage);
    if (b.coverage > 0.0) {
      s.inverse_depth_per_mm = b.inverse_depth / b.coverage;
      s.coc_px = b.coc / b.coverage;
    }
    if (b.weight > 0.0) {
      const double cx = b.x / b.weight, cy = b.y / b.weight;
      s.x = std::clamp(static_cast<int>(std::floor(cx)), 0, width - 1);
      s.y = std::clamp(static_cast<int>(std::floor(cy)), 0, height - 1);
      s.offset_x_px = static_cast<float>(cx - (s.x + 0.5));
      s.offset_y_px = static_cast<float>(cy - (s.y + 0.5));
    }
    merged_layer.push_back(s);
  }
  // Swapped, so that both vectors keep their memory for the next layer.
  layer.swap(merged_layer);
}

}  // namespace lensmith::render_detail

#include "hidden_surfaces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <omp.h>

#include "first_touch.h"
#include "push_pull.h"

namespace lensmith::render_detail {

namespace {
// The interpolation's tone map and its inverse (capped so that the inverse stays finite).
constexpr double kMaxTone = 0.999;
double tone(float v) { return static_cast<double>(v) / (1.0 + static_cast<double>(v)); }
float untone(double t) { return static_cast<float>(std::min(t, kMaxTone) / (1.0 - std::min(t, kMaxTone))); }
}  // namespace

std::size_t append_hidden_sources(const ScatterSources& sources, const DepthLayers& layers, int layer, int width, int height,
                                  double reach_px, HiddenSurfaces mode, const Camera& camera, int threads,
                                  HiddenScratch& scratch, ScatterSources& out) {
  const int w = width, h = height;
  const int reach = static_cast<int>(reach_px);
  // Only pixels within the reach of the layer's own can be targets: the dilation below runs over the
  // bounding box of the layer's pixels in the frame widened by the reach (a layer of a few distant
  // lights costs that box, not the frame).
  int bx0 = w, bx1 = -1, by0 = h, by1 = -1;
  const std::span<const int> members = layers.members(layer);
  const auto member_count = static_cast<std::ptrdiff_t>(members.size());
  // Where the first w x h sources are the frame's pixels in raster order (a flat picture's), a member
  // below w x h is the pixel of its index: its rows are those of the first and last such member (the
  // members are in source order), and its columns are found without reading the sources, walked by
  // rows, until they span the frame. (Reading every member's source, 56 bytes each, took the fence's
  // wall at 6 m 0.3 ms.) The members after them (split pixels' far parts, the margin) are read.
  const std::ptrdiff_t pixel_members =
      layers.pixels_first ? std::lower_bound(members.begin(), members.end(), w * h) - members.begin() : 0;
  if (pixel_members > 0) {
    by0 = members.front() / w;
    by1 = members[static_cast<std::size_t>(pixel_members) - 1] / w;
#pragma omp parallel num_threads(threads) reduction(min : bx0) reduction(max : bx1)
    {
      const std::ptrdiff_t t = omp_get_thread_num(), n = omp_get_num_threads();
      const std::ptrdiff_t first = pixel_members * t / n, last = pixel_members * (t + 1) / n;
      int row_start = first < last ? members[static_cast<std::size_t>(first)] / w * w : 0;
      for (std::ptrdiff_t k = first; k < last && !(bx0 == 0 && bx1 == w - 1); ++k) {
        const int i = members[static_cast<std::size_t>(k)];
        while (i >= row_start + w) row_start += w;
        bx0 = std::min(bx0, i - row_start);
        bx1 = std::max(bx1, i - row_start);
      }
    }
  }
#pragma omp parallel for num_threads(threads) schedule(static) reduction(min : bx0, by0) reduction(max : bx1, by1)
  for (std::ptrdiff_t k = pixel_members; k < member_count; ++k) {
    const ScatterSource& p = sources[static_cast<std::size_t>(members[static_cast<std::size_t>(k)])];
    if (p.x < 0 || p.y < 0 || p.x >= w || p.y >= h) continue;  // the scatter's margin
    bx0 = std::min(bx0, p.x);
    bx1 = std::max(bx1, p.x);
    by0 = std::min(by0, p.y);
    by1 = std::max(by1, p.y);
  }
  if (bx1 < bx0) return 0;
  bx0 = std::max(0, bx0 - reach);
  by0 = std::max(0, by0 - reach);
  bx1 = std::min(w - 1, bx1 + reach);
  by1 = std::min(h - 1, by1 + reach);
  const int bw = bx1 - bx0 + 1, bh = by1 - by0 + 1;
  // Nearer pixels within a (2 reach + 1)-pixel square of a pixel of the layer: a separable
  // dilation, rows then columns, each line independent (threads).
  const int far = std::numeric_limits<int>::max() / 4;
  auto frame_index = [w, bx0, by0](int bx, int by) { return static_cast<std::size_t>(by0 + by) * w + static_cast<std::size_t>(bx0 + bx); };
  UnconstructedVector<int>& row_distance = scratch.row_distance;
  row_distance.resize(static_cast<std::size_t>(bw) * bh);  // every entry is written below
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < bh; ++y) {
    int* d = row_distance.data() + static_cast<std::size_t>(y) * bw;
    const std::size_t row = frame_index(0, y);
    int last = far;
    for (int x = 0; x < bw; ++x) d[x] = layers.in(row + x, layer) ? (last = 0) : (last = std::min(far, last + 1));
    last = far;
    // (A pixel of the layer is one the forward pass gave 0: its parts are not walked again.)
    for (int x = bw - 1; x >= 0; --x) d[x] = std::min(d[x], d[x] == 0 ? (last = 0) : (last = std::min(far, last + 1)));
  }
  UnconstructedVector<std::uint8_t>& within = scratch.within;
  within.resize(static_cast<std::size_t>(bw) * bh);  // every entry is written below
  // Columns down and up, each thread a block of them walked row by row with one running distance
  // per column: walked column by column, every step jumped a row.
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), n = omp_get_num_threads();
    const int xa = static_cast<int>(static_cast<long long>(bw) * t / n), xb = static_cast<int>(static_cast<long long>(bw) * (t + 1) / n);
    std::vector<int> last;
    // Rows from y_first by `step` (+1 down, -1 up); the first pass writes `within`, the second adds to it.
    auto pass = [&](int y_first, int step, bool first) {
      last.assign(static_cast<std::size_t>(std::max(0, xb - xa)), far);
      for (int y = y_first; y >= 0 && y < bh; y += step) {
        const int* d = row_distance.data() + static_cast<std::size_t>(y) * bw;
        std::uint8_t* in = within.data() + static_cast<std::size_t>(y) * bw;
        for (int x = xa; x < xb; ++x) {
          int& l = last[static_cast<std::size_t>(x - xa)];
          l = d[x] <= reach ? 0 : std::min(far, l + 1);
          in[x] = ((!first && in[x]) || l <= reach) ? 1 : 0;
        }
      }
    };
    pass(0, 1, true);
    pass(bh - 1, -1, false);
  }
  // The targets, in row order: each thread scans a block of rows into its own list (the box is up
  // to the frame, once per layer).
  const int blocks = std::max(1, std::min(threads, bh));
  scratch.block_targets.resize(static_cast<std::size_t>(blocks));
  std::vector<std::array<int, 4>> block_box(static_cast<std::size_t>(blocks), std::array<int, 4>{w, -1, h, -1});
#pragma omp parallel for num_threads(threads) schedule(static, 1)
  for (int b = 0; b < blocks; ++b) {
    std::vector<std::size_t>& found = scratch.block_targets[static_cast<std::size_t>(b)];
    std::array<int, 4>& box = block_box[static_cast<std::size_t>(b)];
    found.clear();
    for (int y = static_cast<int>(static_cast<long long>(bh) * b / blocks); y < static_cast<int>(static_cast<long long>(bh) * (b + 1) / blocks); ++y) {
      for (int x = 0; x < bw; ++x) {
        if (!within[static_cast<std::size_t>(y) * bw + x]) continue;
        const std::size_t i = frame_index(x, y);
        if (!(layers.unknown_behind(i, layer) > 0.0f)) continue;
        found.push_back(i);
        box = {std::min(box[0], bx0 + x), std::max(box[1], bx0 + x), std::min(box[2], by0 + y), std::max(box[3], by0 + y)};
      }
    }
  }
  std::vector<std::size_t>& targets = scratch.targets;
  targets.clear();
  int x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (int b = 0; b < blocks; ++b) {
    const std::vector<std::size_t>& found = scratch.block_targets[static_cast<std::size_t>(b)];
    targets.insert(targets.end(), found.begin(), found.end());
    const std::array<int, 4>& box = block_box[static_cast<std::size_t>(b)];
    x0 = std::min(x0, box[0]);
    x1 = std::max(x1, box[1]);
    y0 = std::min(y0, box[2]);
    y1 = std::max(y1, box[3]);
  }
  if (targets.empty()) return 0;
  // Push-pull over the window of the targets widened by the reach, where the layer's pixels that
  // feed them lie.
  x0 = std::max(0, x0 - reach);
  y0 = std::max(0, y0 - reach);
  x1 = std::min(w - 1, x1 + reach);
  y1 = std::min(h - 1, y1 + reach);
  const int ww = x1 - x0 + 1, wh = y1 - y0 + 1;
  // The targets' cells in the window: the only ones of its finest level the push-pulls finish.
  std::vector<std::size_t>& target_cells = scratch.target_cells;
  target_cells.resize(targets.size());
  for (std::size_t k = 0; k < targets.size(); ++k) {
    const std::size_t i = targets[k];
    target_cells[k] = (i / static_cast<std::size_t>(w) - static_cast<std::size_t>(y0)) * static_cast<std::size_t>(ww) +
                      (i % static_cast<std::size_t>(w) - static_cast<std::size_t>(x0));
  }
  // The push-pulls' finest level is never made: the window's pixels are summed into level 1
  // directly, rows first within each 2 x 2 block as the pull sums them (so the same floats), and the
  // targets' own pixels apart (push_pull_targets). A window-sized finest level (20 + 8 bytes a
  // pixel) was zeroed, filled and read again for every layer.
  const int cw = (ww + 1) / 2, ch = (wh + 1) / 2;
  // The whole frame's address space once (reserve is free until touched), so that no layer's
  // larger window moves the levels to fresh memory.
  scratch.push_pull.reserve(w, h);
  LargeVector<PushPullCell<5>>& first = push_pull_first_level(ww, wh, scratch.push_pull);
  std::vector<PushPullCell<5>>& own = scratch.own;
  own.assign(targets.size(), PushPullCell<5>{});
  // The layer's own whole pixels (the parts of split edge pixels are uncertain estimates). Each thread
  // adds those of its block of level 1's rows, in the members' order (raster order; a deep pixel's
  // opaque samples may share a cell), so the sums are the same whatever the threads; a member on a
  // target's pixel goes to that target's own sums too (the targets are in raster order).
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), n = omp_get_num_threads();
    const int cya = static_cast<int>(static_cast<long long>(ch) * t / n), cyb = static_cast<int>(static_cast<long long>(ch) * (t + 1) / n);
    std::fill(first.begin() + static_cast<std::ptrdiff_t>(cya) * cw, first.begin() + static_cast<std::ptrdiff_t>(cyb) * cw,
              PushPullCell<5>{});
    const int ya = y0 + 2 * cya, yb = std::min(y1 + 1, y0 + 2 * cyb);
    const std::ptrdiff_t target_first =
        std::lower_bound(targets.begin(), targets.end(), static_cast<std::size_t>(ya) * static_cast<std::size_t>(w)) - targets.begin();
    std::ptrdiff_t k = target_first;
    std::size_t last_pixel = 0;
    // Members are in source order. Where the first w x h sources are the pixels in raster order (a
    // flat picture's), the thread's rows of them are found by bisection among the pixel members and
    // the rest skipped, then the parts appended after them are looked at; else every member.
    auto rows_begin = members.begin(), rows_end = members.end(), appended = members.end();
    if (layers.pixels_first) {
      appended = members.begin() + pixel_members;
      const auto below = [](int i, std::size_t v) { return static_cast<std::size_t>(i) < v; };
      rows_begin = std::lower_bound(members.begin(), appended, static_cast<std::size_t>(ya) * static_cast<std::size_t>(w), below);
      rows_end = std::lower_bound(rows_begin, appended, static_cast<std::size_t>(yb) * static_cast<std::size_t>(w), below);
    }
    for (auto it = rows_begin; it != members.end(); ++it) {
      if (it == rows_end) {
        it = appended;
        if (it == members.end()) break;
      }
      const int i = *it;
      const ScatterSource& p = sources[static_cast<std::size_t>(i)];
      if (p.y < ya || p.y >= yb || p.x < x0 || p.x > x1 || p.coverage < 1.0f) continue;
      const double c = p.coverage;
      const PushPullCell<5> v{static_cast<float>(c * tone(p.rgb[0] / p.coverage)), static_cast<float>(c * tone(p.rgb[1] / p.coverage)),
                              static_cast<float>(c * tone(p.rgb[2] / p.coverage)), static_cast<float>(c * p.inverse_depth_per_mm),
                              static_cast<float>(c)};
      PushPullCell<5>& cell = first[static_cast<std::size_t>((p.y - y0) / 2) * cw + static_cast<std::size_t>((p.x - x0) / 2)];
      for (std::size_t q = 0; q < 5; ++q) cell[q] += v[q];
      // The next target at or after this pixel (searched again where a member comes out of order).
      const std::size_t pixel = static_cast<std::size_t>(p.y) * w + static_cast<std::size_t>(p.x);
      if (pixel < last_pixel) k = std::lower_bound(targets.begin() + target_first, targets.end(), pixel) - targets.begin();
      last_pixel = pixel;
      while (k < static_cast<std::ptrdiff_t>(targets.size()) && targets[static_cast<std::size_t>(k)] < pixel) ++k;
      if (k < static_cast<std::ptrdiff_t>(targets.size()) && targets[static_cast<std::size_t>(k)] == pixel) {
        for (std::size_t q = 0; q < 5; ++q) own[static_cast<std::size_t>(k)][q] += v[q];
      }
    }
  }
  push_pull_targets<5>(ww, wh, scratch.push_pull, target_cells, own, threads);
  // The layer's share of what lies behind the nearer pixels: among the visible parts of this layer
  // and of every farther one, the fraction on this layer, interpolated by the same push-pull. Each
  // farther layer claims only its share, so that composited "over" one another the layers behind an
  // occluder mix as their pixels around it do. Without it every layer claimed all of it, and the
  // nearest of them hid the others: a branch crossing behind a nearer one was extended under the
  // whole of the nearer branch's blur, 17 % too bright there (examples/scenes/branches.json).
  // (None to compute where no farther layer shows in the window: the layer claims all of it; none
  // where no source at all lies on a farther layer, as behind the fence's wall: no scan.)
  bool farther = false;
  const bool any_farther = layers.member_begin[static_cast<std::size_t>(layer)] > layers.member_begin[0];
  for (int y = y0; y <= y1 && any_farther && !farther; ++y) {
    for (int x = x0; x <= x1 && !farther; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      for (std::uint32_t k = layers.part_begin[p]; k < layers.part_begin[p + 1]; ++k) farther = farther || layers.parts[k].layer < layer;
    }
  }
  std::vector<PushPullCell<2>>& own_shares = scratch.own_shares;
  if (farther) {
    // A pixel's cell: its parts on this layer and on this or farther ones.
    auto share_cell = [&](int x, int y) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      PushPullCell<2> cell{};
      for (std::uint32_t k = layers.part_begin[p]; k < layers.part_begin[p + 1]; ++k) {
        const PixelPart& part = layers.parts[k];
        if (part.layer > layer) continue;
        if (part.layer == layer) cell[0] += part.visible;
        cell[1] += part.visible;
      }
      return cell;
    };
    scratch.push_pull_shares.reserve(w, h);
    LargeVector<PushPullCell<2>>& first_shares = push_pull_first_level(ww, wh, scratch.push_pull_shares);
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int cy = 0; cy < ch; ++cy) {
      for (int cx = 0; cx < cw; ++cx) {
        PushPullCell<2> sum{};
        for (int y = y0 + 2 * cy; y < std::min(y1 + 1, y0 + 2 * cy + 2); ++y) {
          for (int x = x0 + 2 * cx; x < std::min(x1 + 1, x0 + 2 * cx + 2); ++x) {
            const PushPullCell<2> cell = share_cell(x, y);
            sum[0] += cell[0];
            sum[1] += cell[1];
          }
        }
        first_shares[static_cast<std::size_t>(cy) * cw + static_cast<std::size_t>(cx)] = sum;
      }
    }
    own_shares.resize(targets.size());
    const auto count = static_cast<std::ptrdiff_t>(targets.size());
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::ptrdiff_t k = 0; k < count; ++k) {
      const std::size_t i = targets[static_cast<std::size_t>(k)];
      own_shares[static_cast<std::size_t>(k)] = share_cell(static_cast<int>(i % static_cast<std::size_t>(w)), static_cast<int>(i / static_cast<std::size_t>(w)));
    }
    push_pull_targets<2>(ww, wh, scratch.push_pull_shares, target_cells, own_shares, threads);
  }
  // One source per target, made in parallel in the targets' order; those with nothing hidden to
  // stand for (no coverage) are dropped after.
  const std::size_t before = out.size();
  fault_in(out, before + targets.size(), threads);
  out.resize(before + targets.size());
  const auto target_count = static_cast<std::ptrdiff_t>(targets.size());
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t k = 0; k < target_count; ++k) {
    const auto u = static_cast<std::size_t>(k);
    const std::size_t i = targets[u];
    const auto& v = own[u];
    ScatterSource& s = out[before + u];
    s = ScatterSource{};
    s.x = static_cast<int>(i % static_cast<std::size_t>(w));
    s.y = static_cast<int>(i / static_cast<std::size_t>(w));
    const double share = farther ? own_shares[u][0] : 1.0;
    s.coverage = layers.unknown_behind(i, layer) * static_cast<float>(share);
    if (!(s.coverage > 0.0f)) continue;
    s.coverage_only = mode == HiddenSurfaces::Stretch;
    if (!s.coverage_only) s.rgb = {s.coverage * untone(v[0]), s.coverage * untone(v[1]), s.coverage * untone(v[2])};
    s.inverse_depth_per_mm = v[3];
    s.coc_px = camera.signed_coc_px(v[3]);
  }
  out.erase(std::remove_if(out.begin() + static_cast<std::ptrdiff_t>(before), out.end(),
                           [](const ScatterSource& s) { return !(s.coverage > 0.0f); }),
            out.end());
  return out.size() - before;
}

}  // namespace lensmith::render_detail

#include "push_pull.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lensmith::render_detail {

namespace {

// Levels with fewer cells than this are done on one thread (starting threads would cost more). The
// renderer's threads are awake and waiting by then: at 16384, a full frame's second level (15 000
// cells of a 600 x 400 window) was pushed on one thread in every layer's two push-pulls; at 2048 the
// street at f/4's hidden-surface stage (7 layers) went from 7.12 to 6.75 ms (medians of 31,
// alternately), and 512 was no better.
constexpr int kParallelCells = 2048;

// Normalised value of a cell of sums: the N - 1 values divided by the weight, and its confidence
// min(weight, 1) in the last slot (Gortler et al. clamp the pulled weights to 1 the same way).
template <std::size_t N>
PushPullCell<N> normalised(const PushPullCell<N>& v) {
  constexpr std::size_t kWeight = N - 1;
  if (!(v[kWeight] > 0.0f)) return {};
  PushPullCell<N> n;
  for (std::size_t k = 0; k < kWeight; ++k) n[k] = v[k] / v[kWeight];
  n[kWeight] = std::min(v[kWeight], 1.0f);
  return n;
}

// The pull and the push of push_pull. `cells`: the finest level, or null where the caller gave level
// 1 in levels[0] and the finest level only at `finish` (`own`).
template <std::size_t N>
void run_push_pull(int w, int h, LargeVector<PushPullCell<N>>* cells, int threads, std::vector<LargeVector<PushPullCell<N>>>& levels,
                   std::span<const std::size_t> finish, std::span<PushPullCell<N>> own) {
  using Cell = PushPullCell<N>;
  constexpr std::size_t kWeight = N - 1;
  // Pull: each level sums 2 x 2 blocks of the one below, down to a single cell.
  std::vector<std::pair<int, int>> sizes{{w, h}};
  if (!cells && (w > 1 || h > 1)) sizes.push_back({(w + 1) / 2, (h + 1) / 2});  // given
  while (sizes.back().first > 1 || sizes.back().second > 1) {
    const int fw = sizes.back().first, fh = sizes.back().second;
    const int cw = (fw + 1) / 2, ch = (fh + 1) / 2;
    if (levels.size() < sizes.size()) levels.emplace_back();
    const LargeVector<Cell>& f = sizes.size() == 1 ? *cells : levels[sizes.size() - 2];
    LargeVector<Cell>& c = levels[sizes.size() - 1];
    c.resize(static_cast<std::size_t>(cw) * ch);  // every cell is written below
    // Each coarse row from its two fine rows: rows are independent.
#pragma omp parallel for num_threads(threads) schedule(static) if (fw * fh > kParallelCells)
    for (int cy = 0; cy < ch; ++cy) {
      Cell* dst = c.data() + static_cast<std::size_t>(cy) * cw;
      for (int x = 0; x < cw; ++x) dst[x] = Cell{};
      for (int y = 2 * cy; y < std::min(fh, 2 * cy + 2); ++y) {
        const Cell* src = f.data() + static_cast<std::size_t>(y) * fw;
        for (int x = 0; x < fw; ++x) {
          for (std::size_t k = 0; k < N; ++k) dst[x / 2][k] += src[x][k];
        }
      }
    }
    sizes.push_back({cw, ch});
  }
  const std::size_t level_count = sizes.size() - 1;
  if (level_count == 0) {  // a single cell
    for (Cell& one : cells ? std::span<Cell>(cells->data(), 1) : own) {
      one = normalised(one);
      if (one[kWeight] > 0.0f) one[kWeight] = 1.0f;
    }
    return;
  }
  // Push: from the coarsest level down, every cell becomes its own normalised value blended by its
  // confidence with the bilinear interpolation of the finished level above (cell centres at
  // (x + 0.5) / 2 - 0.5 in its coordinates), so that filled areas are smooth, not 2^k blocks.
  Cell& top = levels[level_count - 1][0];
  top = normalised(top);
  if (top[kWeight] > 0.0f) top[kWeight] = 1.0f;
  for (std::size_t l = level_count; l-- > 0;) {
    // (Level 0 without its cells: only `own`'s, below.)
    Cell* const f = l == 0 ? (cells ? cells->data() : nullptr) : levels[l - 1].data();
    const LargeVector<Cell>& c = levels[l];
    const int fw = sizes[l].first, fh = sizes[l].second;
    const int cw = sizes[l + 1].first, ch = sizes[l + 1].second;
    // Row y's rows of the level above and the weight between them.
    struct Above {
      int y0, y1;
      double ty;
    };
    auto above = [&](int y) {
      const double cy = std::clamp((y + 0.5) / 2.0 - 0.5, 0.0, static_cast<double>(ch - 1));
      const int y0 = static_cast<int>(cy);
      return Above{y0, std::min(y0 + 1, ch - 1), cy - y0};
    };
    // Cell `v` (column x, its row's levels above `r`) of level l from its own sums and the finished level above.
    auto push = [&](int x, const Above& r, Cell& v) {
      const int y0 = r.y0, y1 = r.y1;
      const double ty = r.ty;
      const double cx = std::clamp((x + 0.5) / 2.0 - 0.5, 0.0, static_cast<double>(cw - 1));
      const int x0 = static_cast<int>(cx), x1 = std::min(x0 + 1, cw - 1);
      const double tx = cx - x0;
      const Cell& a = c[static_cast<std::size_t>(y0) * cw + x0];
      const Cell& b = c[static_cast<std::size_t>(y0) * cw + x1];
      const Cell& d = c[static_cast<std::size_t>(y1) * cw + x0];
      const Cell& e = c[static_cast<std::size_t>(y1) * cw + x1];
      const Cell self = normalised(v);
      const double keep = self[kWeight];
      for (std::size_t k = 0; k < kWeight; ++k) {
        const double up = (1.0 - ty) * ((1.0 - tx) * a[k] + tx * b[k]) + ty * ((1.0 - tx) * d[k] + tx * e[k]);
        v[k] = static_cast<float>(keep * self[k] + (1.0 - keep) * up);
      }
      // Known wherever the level above is (the coarsest cell is known if any cell was).
      v[kWeight] = std::max({a[kWeight], b[kWeight], d[kWeight], e[kWeight], self[kWeight]}) > 0.0f ? 1.0f : 0.0f;
    };
    if (l == 0 && (!finish.empty() || !cells)) {
      // Only the cells the caller reads (their values are the same as when every cell is finished),
      // each on its own (threads): in place, or in `own`.
      const auto row = static_cast<std::size_t>(fw);
      const auto count = static_cast<std::ptrdiff_t>(finish.size());
#pragma omp parallel for num_threads(threads) schedule(static) if (count > kParallelCells / 4)
      for (std::ptrdiff_t k = 0; k < count; ++k) {
        const std::size_t i = finish[static_cast<std::size_t>(k)];
        const auto y = static_cast<int>(i / row);
        push(static_cast<int>(i % row), above(y), f ? f[i] : own[static_cast<std::size_t>(k)]);
      }
      continue;
    }
#pragma omp parallel for num_threads(threads) schedule(static) if (fw * fh > kParallelCells)
    for (int y = 0; y < fh; ++y) {
      const Above r = above(y);
      for (int x = 0; x < fw; ++x) push(x, r, f[static_cast<std::size_t>(y) * fw + x]);
    }
  }
}

}  // namespace

template <std::size_t N>
void push_pull(int w, int h, LargeVector<PushPullCell<N>>& cells, int threads, PushPullScratch<N>* scratch,
               std::span<const std::size_t> finish) {
  PushPullScratch<N> local;
  run_push_pull<N>(w, h, &cells, threads, (scratch ? *scratch : local).levels, finish, {});
}

template <std::size_t N>
LargeVector<PushPullCell<N>>& push_pull_first_level(int w, int h, PushPullScratch<N>& scratch) {
  if (scratch.levels.empty()) scratch.levels.emplace_back();
  scratch.levels[0].resize(static_cast<std::size_t>((w + 1) / 2) * static_cast<std::size_t>((h + 1) / 2));
  return scratch.levels[0];
}

template <std::size_t N>
void push_pull_targets(int w, int h, PushPullScratch<N>& scratch, std::span<const std::size_t> finish, std::span<PushPullCell<N>> own,
                       int threads) {
  run_push_pull<N>(w, h, nullptr, threads, scratch.levels, finish, own);
}

template void push_pull<2>(int, int, LargeVector<PushPullCell<2>>&, int, PushPullScratch<2>*, std::span<const std::size_t>);
template void push_pull<5>(int, int, LargeVector<PushPullCell<5>>&, int, PushPullScratch<5>*, std::span<const std::size_t>);
template LargeVector<PushPullCell<2>>& push_pull_first_level<2>(int, int, PushPullScratch<2>&);
template LargeVector<PushPullCell<5>>& push_pull_first_level<5>(int, int, PushPullScratch<5>&);
template void push_pull_targets<2>(int, int, PushPullScratch<2>&, std::span<const std::size_t>, std::span<PushPullCell<2>>, int);
template void push_pull_targets<5>(int, int, PushPullScratch<5>&, std::span<const std::size_t>, std::span<PushPullCell<5>>, int);

}  // namespace lensmith::render_detail

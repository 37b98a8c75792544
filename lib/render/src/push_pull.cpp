#include "push_pull.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lensmith::render_detail {

namespace {

// Levels with fewer cells than this are done on one thread (starting threads would cost more).
constexpr int kParallelCells = 16384;

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

}  // namespace

template <std::size_t N>
void push_pull(int w, int h, LargeVector<PushPullCell<N>>& cells, int threads, PushPullScratch<N>* scratch,
               std::span<const std::size_t> finish) {
  using Cell = PushPullCell<N>;
  constexpr std::size_t kWeight = N - 1;
  // Pull: each level sums 2 x 2 blocks of the one below, down to a single cell.
  PushPullScratch<N> local;
  std::vector<LargeVector<Cell>>& levels = (scratch ? *scratch : local).levels;
  std::vector<std::pair<int, int>> sizes{{w, h}};
  while (sizes.back().first > 1 || sizes.back().second > 1) {
    const int fw = sizes.back().first, fh = sizes.back().second;
    const int cw = (fw + 1) / 2, ch = (fh + 1) / 2;
    if (levels.size() < sizes.size()) levels.emplace_back();
    const LargeVector<Cell>& f = sizes.size() == 1 ? cells : levels[sizes.size() - 2];
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
    cells[0] = normalised(cells[0]);
    if (cells[0][kWeight] > 0.0f) cells[0][kWeight] = 1.0f;
    return;
  }
  // Push: from the coarsest level down, every cell becomes its own normalised value blended by its
  // confidence with the bilinear interpolation of the finished level above (cell centres at
  // (x + 0.5) / 2 - 0.5 in its coordinates), so that filled areas are smooth, not 2^k blocks.
  Cell& top = levels[level_count - 1][0];
  top = normalised(top);
  if (top[kWeight] > 0.0f) top[kWeight] = 1.0f;
  for (std::size_t l = level_count; l-- > 0;) {
    LargeVector<Cell>& f = l == 0 ? cells : levels[l - 1];
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
    // Cell (x, y) of level l from its own sums and the finished level above.
    auto push = [&](int x, int y, const Above& r) {
      const int y0 = r.y0, y1 = r.y1;
      const double ty = r.ty;
      const double cx = std::clamp((x + 0.5) / 2.0 - 0.5, 0.0, static_cast<double>(cw - 1));
      const int x0 = static_cast<int>(cx), x1 = std::min(x0 + 1, cw - 1);
      const double tx = cx - x0;
      const Cell& a = c[static_cast<std::size_t>(y0) * cw + x0];
      const Cell& b = c[static_cast<std::size_t>(y0) * cw + x1];
      const Cell& d = c[static_cast<std::size_t>(y1) * cw + x0];
      const Cell& e = c[static_cast<std::size_t>(y1) * cw + x1];
      Cell& v = f[static_cast<std::size_t>(y) * fw + x];
      const Cell own = normalised(v);
      const double keep = own[kWeight];
      for (std::size_t k = 0; k < kWeight; ++k) {
        const double up = (1.0 - ty) * ((1.0 - tx) * a[k] + tx * b[k]) + ty * ((1.0 - tx) * d[k] + tx * e[k]);
        v[k] = static_cast<float>(keep * own[k] + (1.0 - keep) * up);
      }
      // Known wherever the level above is (the coarsest cell is known if any cell was).
      v[kWeight] = std::max({a[kWeight], b[kWeight], d[kWeight], e[kWeight], own[kWeight]}) > 0.0f ? 1.0f : 0.0f;
    };
    if (l == 0 && !finish.empty()) {
      // Only the cells the caller reads (their values are the same as when every cell is finished),
      // each on its own (threads).
      const auto row = static_cast<std::size_t>(fw);
      const auto count = static_cast<std::ptrdiff_t>(finish.size());
#pragma omp parallel for num_threads(threads) schedule(static) if (count > kParallelCells / 4)
      for (std::ptrdiff_t k = 0; k < count; ++k) {
        const std::size_t i = finish[static_cast<std::size_t>(k)];
        const auto y = static_cast<int>(i / row);
        push(static_cast<int>(i % row), y, above(y));
      }
      continue;
    }
#pragma omp parallel for num_threads(threads) schedule(static) if (fw * fh > kParallelCells)
    for (int y = 0; y < fh; ++y) {
      const Above r = above(y);
      for (int x = 0; x < fw; ++x) push(x, y, r);
    }
  }
}

template void push_pull<2>(int, int, LargeVector<PushPullCell<2>>&, int, PushPullScratch<2>*, std::span<const std::size_t>);
template void push_pull<5>(int, int, LargeVector<PushPullCell<5>>&, int, PushPullScratch<5>*, std::span<const std::size_t>);

}  // namespace lensmith::render_detail

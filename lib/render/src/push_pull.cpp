#include "push_pull.h"

#include <utility>

namespace lensmith::render_detail {

void push_pull(int w, int h, std::vector<std::array<double, 5>>& cells) {
  std::vector<std::vector<std::array<double, 5>>> levels;
  std::vector<std::pair<int, int>> sizes{{w, h}};
  while (sizes.back().first > 1 || sizes.back().second > 1) {
    const auto [fw, fh] = sizes.back();
    const std::vector<std::array<double, 5>>& f = levels.empty() ? cells : levels.back();
    const int cw = (fw + 1) / 2, ch = (fh + 1) / 2;
    std::vector<std::array<double, 5>> c(static_cast<std::size_t>(cw) * ch, std::array<double, 5>{});
    for (int y = 0; y < fh; ++y) {
      for (int x = 0; x < fw; ++x) {
        auto& dst = c[static_cast<std::size_t>(y / 2) * cw + x / 2];
        const auto& src = f[static_cast<std::size_t>(y) * fw + x];
        for (int k = 0; k < 5; ++k) dst[k] += src[k];
      }
    }
    levels.push_back(std::move(c));
    sizes.push_back({cw, ch});
  }
  auto normalise = [](std::array<double, 5>& v) {
    if (v[4] > 0.0) {
      for (int k = 0; k < 4; ++k) v[k] /= v[4];
      v[4] = 1.0;
    }
  };
  if (!levels.empty()) normalise(levels.back()[0]);
  // Push from the coarsest level to the finest (level index l - 1; cells themselves at the end).
  for (std::size_t l = levels.size(); l-- > 0;) {
    std::vector<std::array<double, 5>>& f = l == 0 ? cells : levels[l - 1];
    const std::vector<std::array<double, 5>>& c = levels[l];
    const auto [fw, fh] = sizes[l];
    const int cw = sizes[l + 1].first;
    for (int y = 0; y < fh; ++y) {
      for (int x = 0; x < fw; ++x) {
        auto& v = f[static_cast<std::size_t>(y) * fw + x];
        if (v[4] > 0.0) {
          normalise(v);
        } else {
          v = c[static_cast<std::size_t>(y / 2) * cw + x / 2];
        }
      }
    }
  }
}

}  // namespace lensmith::render_detail

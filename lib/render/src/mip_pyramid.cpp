#include "mip_pyramid.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lensmith::render_detail {

MipPyramid::MipPyramid(std::vector<std::array<float, 4>> base, int w, int h) {
  levels_.push_back(std::move(base));
  widths_.push_back(w);
  heights_.push_back(h);
  while (w > 1 || h > 1) {
    const int nw = (w + 1) / 2, nh = (h + 1) / 2;
    const auto& prev = levels_.back();
    std::vector<std::array<float, 4>> next(static_cast<std::size_t>(nw) * static_cast<std::size_t>(nh));
    for (int y = 0; y < nh; ++y) {
      for (int x = 0; x < nw; ++x) {
        std::array<float, 4> sum{};
        for (int dy = 0; dy < 2; ++dy) {
          for (int dx = 0; dx < 2; ++dx) {
            const int sx = std::min(2 * x + dx, w - 1), sy = std::min(2 * y + dy, h - 1);
            const auto& v = prev[static_cast<std::size_t>(sy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(sx)];
            for (std::size_t c = 0; c < 4; ++c) sum[c] += 0.25f * v[c];
          }
        }
        next[static_cast<std::size_t>(y) * static_cast<std::size_t>(nw) + static_cast<std::size_t>(x)] = sum;
      }
    }
    levels_.push_back(std::move(next));
    widths_.push_back(nw);
    heights_.push_back(nh);
    w = nw;
    h = nh;
  }
}

std::array<float, 4> MipPyramid::at_level(std::size_t k, float x, float y) const {
  const float scale = 1.0f / static_cast<float>(1 << k);
  const int w = widths_[k], h = heights_[k];
  const float fx = std::clamp(x * scale - 0.5f, 0.0f, static_cast<float>(w - 1));
  const float fy = std::clamp(y * scale - 0.5f, 0.0f, static_cast<float>(h - 1));
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const float tx = fx - static_cast<float>(x0), ty = fy - static_cast<float>(y0);
  const auto& level = levels_[k];
  auto at = [&](int xi, int yi) -> const std::array<float, 4>& {
    return level[static_cast<std::size_t>(yi) * static_cast<std::size_t>(w) + static_cast<std::size_t>(xi)];
  };
  std::array<float, 4> out{};
  for (std::size_t c = 0; c < 4; ++c) {
    out[c] = (1 - tx) * (1 - ty) * at(x0, y0)[c] + tx * (1 - ty) * at(x1, y0)[c] + (1 - tx) * ty * at(x0, y1)[c] + tx * ty * at(x1, y1)[c];
  }
  return out;
}

std::array<float, 4> MipPyramid::window(float x, float y, float diameter) const {
  const float level = std::clamp(std::log2(diameter), 0.0f, static_cast<float>(levels_.size() - 1));
  const auto k0 = static_cast<std::size_t>(level);
  const std::size_t k1 = std::min(k0 + 1, levels_.size() - 1);
  const float t = level - static_cast<float>(k0);
  const std::array<float, 4> a = at_level(k0, x, y), b = at_level(k1, x, y);
  std::array<float, 4> out{};
  for (std::size_t c = 0; c < 4; ++c) out[c] = (1 - t) * a[c] + t * b[c];
  return out;
}

}  // namespace lensmith::render_detail

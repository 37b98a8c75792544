// A spot's light, centroid and second moments (px) in one channel of a picture, over a window of it
// or the whole: for tests that compare a highlight's bokeh with the exact tracer's or the ground
// truth's in place, size and shape. Header-only: its users link the render layer.
#pragma once

#include <cmath>

#include "lensmith/render/image.h"

namespace lensmith::testing {

struct SpotMoments {
  double light = 0.0, x = 0.0, y = 0.0;  // total, and centroid (pixel centres at +0.5)
  double xx = 0.0, yy = 0.0, xy = 0.0;   // central second moments, px^2
  double rms() const { return std::sqrt(xx + yy); }  // RMS radius
  // The extent along the spot's long and short axes: the square roots of its moment matrix's eigenvalues.
  double major() const { return std::sqrt(0.5 * (xx + yy) + std::sqrt(0.25 * (xx - yy) * (xx - yy) + xy * xy)); }
  double minor() const { return std::sqrt(0.5 * (xx + yy) - std::sqrt(0.25 * (xx - yy) * (xx - yy) + xy * xy)); }
};

// Over the w x h window at (x0, y0), which must lie inside the picture.
inline SpotMoments spot_moments(const Image& img, int channel, int x0, int y0, int w, int h) {
  SpotMoments s;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      const double v = img.at(x, y, channel);
      s.light += v;
      s.x += v * (x + 0.5);
      s.y += v * (y + 0.5);
    }
  }
  s.x /= s.light;
  s.y /= s.light;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      const double v = img.at(x, y, channel), dx = x + 0.5 - s.x, dy = y + 0.5 - s.y;
      s.xx += v * dx * dx;
      s.yy += v * dy * dy;
      s.xy += v * dx * dy;
    }
  }
  s.xx /= s.light;
  s.yy /= s.light;
  s.xy /= s.light;
  return s;
}

inline SpotMoments spot_moments(const Image& img, int channel) { return spot_moments(img, channel, 0, 0, img.width, img.height); }

}  // namespace lensmith::testing

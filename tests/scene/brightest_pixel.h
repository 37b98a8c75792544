// The centre of the brightest pixel of channel 1 (green), for tests that follow a highlight.
#pragma once

#include "lensmith/camera/pinhole_frame.h"
#include "lensmith/render/image.h"

namespace lensmith::testing {

inline PixelPoint brightest(const Image& image) {
  PixelPoint best;
  float level = -1.0f;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (image.at(x, y, 1) > level) {
        level = image.at(x, y, 1);
        best = {x + 0.5, y + 0.5};
      }
    }
  }
  return best;
}

}  // namespace lensmith::testing

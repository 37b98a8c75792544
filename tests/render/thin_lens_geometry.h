// The thin-lens geometry the depth-of-field methods' tests compare against (pbrt-v3 sec. 6.2.3: a
// ray from lens point a towards the focus-plane point of its pixel): a 50 mm f/2 thin lens on an
// 18 mm wide sensor, the share of its lens disc on one side of a line, and a textured picture.
#pragma once

#include <cmath>

#include "lensmith/camera/camera.h"
#include "lensmith/core/units.h"
#include "lensmith/render/image.h"

namespace lensmith::test {

inline constexpr double kThinFocalLengthMm = 50.0;
inline constexpr double kThinFNumber = 2.0;

inline Camera thin_camera(int w, int h, double focus_m) {
  CameraOptions o;
  o.focus_distance_m = focus_m;
  o.f_number = kThinFNumber;
  o.framing.sensor_width_mm = 18.0;
  return Camera::thin_lens(kThinFocalLengthMm, o, w, h);
}

// The planar depth (m) in front of the focus plane at `focus_m` where `camera` blurs a point to
// `blur_px` (its circle of confusion's diameter, output px), by bisection.
inline double near_depth_for_blur(const Camera& camera, double focus_m, double blur_px) {
  double near = 0.05, far = focus_m;  // blur grows as the depth nears the lens
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (near + far);
    (std::abs(camera.signed_coc_px(inverse_depth_per_mm(mid))) > blur_px ? near : far) = mid;
  }
  return 0.5 * (near + far);
}

// Share of the unit disc left of the line x = c.
inline double disc_share_left_of(double c) {
  if (c <= -1.0) return 0.0;
  if (c >= 1.0) return 1.0;
  return 0.5 + (c * std::sqrt(1.0 - c * c) + std::asin(c)) / kPi;
}

// A w x h picture with detail in every channel and bright dots (4.0) every fifth diagonal: what a
// method must bring back unchanged in focus.
inline Image textured_image(int w, int h) {
  Image image(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      image.at(x, y, 0) = 0.1f + 0.03f * static_cast<float>(x % 11);
      image.at(x, y, 1) = (x + y) % 5 == 0 ? 4.0f : 0.2f;
      image.at(x, y, 2) = 0.05f * static_cast<float>(y % 7);
    }
  }
  return image;
}

}  // namespace lensmith::test

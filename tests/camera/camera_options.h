// Camera options of the camera tests: focus and f-number, the framing left at its defaults.
#pragma once

#include "lensmith/camera/camera.h"

namespace lensmith::testing {

inline CameraOptions camera_options(double focus_m, double f_number) {
  CameraOptions o;
  o.focus_distance_m = focus_m;
  o.f_number = f_number;
  return o;
}

}  // namespace lensmith::testing

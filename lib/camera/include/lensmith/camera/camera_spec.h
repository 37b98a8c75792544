// What a user says about the camera of a render, before it is assembled: a prescription or the
// ideal thin lens of a focal length, the f-number, the focus, the framing and the frame's size. One
// home for the rule that turns it into a Camera, used by every command that photographs (`lensmith
// bokeh`, `scene render`, `validate`) and by the Python module.
#pragma once

#include <optional>
#include <ostream>
#include <string>

#include "lensmith/camera/camera.h"
#include "lensmith/camera/ray_model.h"

namespace lensmith {

struct CameraSpec {
  // The ideal thin lens of this focal length (mm, finite and > 0); unset: the prescription given to
  // camera().
  std::optional<double> thin_lens_focal_length_mm;
  CameraOptions options;  // f-number, focus distance (m, from the entrance pupil), framing
  int width_px = 0;       // the frame, pixels (>= 1)
  int height_px = 0;

  // Throws OptionsError naming the field: a frame under 1 px, a thin lens's focal length not finite
  // and > 0.
  void validate() const;
  std::string to_string() const;  // "CameraSpec(thin lens f = 50 mm, f/1.4, focus 3 m, 600 x 400 px)"
  friend std::ostream& operator<<(std::ostream& os, const CameraSpec& s) { return os << s.to_string(); }

  // The camera a model of `kind` renders with: the ideal thin lens of thin_lens_focal_length_mm
  // when given (kind must then be Thin); for Thin with a prescription, the ideal thin lens of the
  // lens's focal length and, unless the options set one, its f-number; otherwise the prescription
  // (Camera::from_lens). Throws UsageError for a thin lens with another kind or neither lens nor
  // focal length, and what the Camera factories throw.
  Camera camera(RayModelKind kind, const Prescription* lens) const;

  // The focus distance from the entrance pupil (what CameraOptions::focus_distance_m means) of
  // this camera focused at `image_plane_distance_m` from its image plane, as camera metadata
  // measures it (OpenEXR's focus): the sensor-to-pupil distance grows as the lens focuses nearer,
  // so it is solved by fixed-point iteration on camera()'s sensor position (a few steps: the sensor
  // moves by the focus change times the squared magnification). Throws ComputationError when the
  // distance is too short for the lens to focus.
  double pupil_focus_distance_m(RayModelKind kind, const Prescription* lens, double image_plane_distance_m) const;
};

}  // namespace lensmith

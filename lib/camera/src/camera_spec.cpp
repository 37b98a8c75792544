#include "lensmith/camera/camera_spec.h"

#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace lensmith {

namespace {

// The fixed-point iteration of pupil_focus_distance_m: converged when a step moves the focus by
// less than this fraction of it (double rounding of the sensor position), given up after kMaxSteps
// (it gains about a factor of the squared magnification per step).
constexpr double kFocusRelativeTolerance = 1e-12;
constexpr int kMaxFocusSteps = 50;

}  // namespace

void CameraSpec::validate() const {
  if (width_px < 1 || height_px < 1) {
    throw OptionsError("CameraSpec: the frame is " + std::to_string(width_px) + " x " + std::to_string(height_px) +
                       " px: both sides must be >= 1");
  }
  if (thin_lens_focal_length_mm && !(std::isfinite(*thin_lens_focal_length_mm) && *thin_lens_focal_length_mm > 0.0)) {
    throw OptionsError("CameraSpec::thin_lens_focal_length_mm = " + format_number(*thin_lens_focal_length_mm) +
                       ": must be finite and > 0");
  }
}

std::string CameraSpec::to_string() const {
  std::ostringstream os;
  os << "CameraSpec(";
  if (thin_lens_focal_length_mm) {
    os << "thin lens f = " << format_number(*thin_lens_focal_length_mm) << " mm";
  } else {
    os << "a prescription";
  }
  if (options.f_number) os << ", f/" << format_number(*options.f_number);
  os << ", focus " << format_number(options.focus_distance_m) << " m, " << width_px << " x " << height_px << " px)";
  return os.str();
}

Camera CameraSpec::camera(RayModelKind kind, const Prescription* lens) const {
  validate();
  if (thin_lens_focal_length_mm) {
    if (kind != RayModelKind::Thin) {
      throw UsageError("an ideal thin lens has no prescription: only the thin model applies (got " + std::string(lensmith::to_string(kind)) +
                       ")");
    }
    return Camera::thin_lens(*thin_lens_focal_length_mm, options, width_px, height_px);
  }
  if (!lens) throw UsageError("a camera needs a lens (a prescription) or a thin lens's focal length");
  if (kind == RayModelKind::Thin) return Camera::thin_lens_for(*lens, options, width_px, height_px);
  return Camera::from_lens(*lens, options, width_px, height_px);
}

double CameraSpec::pupil_focus_distance_m(RayModelKind kind, const Prescription* lens, double image_plane_distance_m) const {
  CameraSpec at = *this;
  double s = image_plane_distance_m;
  for (int step = 0; step < kMaxFocusSteps; ++step) {
    at.options.focus_distance_m = s;
    const Camera c = at.camera(kind, lens);
    const double next = image_plane_distance_m - m_from_mm(c.z_sensor_mm() - c.z_perspective_mm());
    if (!(next > 0.0)) {
      throw ComputationError("a focus distance of " + format_number(image_plane_distance_m) +
                             " m from the image plane is shorter than the lens's own length to its sensor: the lens cannot focus there");
    }
    if (std::abs(next - s) <= kFocusRelativeTolerance * image_plane_distance_m) return next;
    s = next;
  }
  throw ComputationError("focus " + format_number(image_plane_distance_m) + " m from the image plane: no focus distance from the pupil found");
}

}  // namespace lensmith

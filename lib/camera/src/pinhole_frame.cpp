#include "lensmith/camera/pinhole_frame.h"

#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"

namespace lensmith {

void PinholeFrameOptions::validate() const {
  if (!(std::isfinite(sensor_width_mm) && sensor_width_mm > 0.0)) {
    throw OptionsError("sensor width must be a finite length > 0 mm (got " + format_number(sensor_width_mm) + ")");
  }
  if (focal_length_mm && !(std::isfinite(*focal_length_mm) && *focal_length_mm > 0.0)) {
    throw OptionsError("pinhole focal length must be a finite length > 0 mm (got " + format_number(*focal_length_mm) + ")");
  }
  if (horizontal_fov_deg && !(*horizontal_fov_deg > 0.0 && *horizontal_fov_deg < 180.0)) {
    throw OptionsError("horizontal field of view must lie strictly between 0 and 180 degrees (got " +
                       format_number(*horizontal_fov_deg) + ")");
  }
  if (horizontal_fov_deg && focal_length_mm) {
    throw OptionsError("give either a pinhole focal length or a horizontal field of view, not both");
  }
}

std::string PinholeFrameOptions::to_string() const {
  std::ostringstream os;
  os << "PinholeFrameOptions(sensor width " << sensor_width_mm << " mm";
  if (focal_length_mm) os << ", f " << *focal_length_mm << " mm";
  if (horizontal_fov_deg) os << ", hfov " << *horizontal_fov_deg << " deg";
  os << ")";
  return os.str();
}

PinholeFrame::PinholeFrame(int width_px, int height_px, double focal_length_px)
    : width_(width_px), height_(height_px), focal_px_(focal_length_px), centre_x_(0.5 * width_px), centre_y_(0.5 * height_px) {
  if (width_px < 1 || height_px < 1) throw OptionsError("pinhole image must be at least 1 x 1 pixel");
  if (!(std::isfinite(focal_length_px) && focal_length_px > 0.0)) {
    throw OptionsError("pinhole focal length in pixels must be finite and > 0 (got " + format_number(focal_length_px) + ")");
  }
}

PinholeFrame PinholeFrame::window(int left, int top, int width_px, int height_px) const {
  PinholeFrame part(width_px, height_px, focal_px_);
  part.centre_x_ = centre_x_ - left;
  part.centre_y_ = centre_y_ - top;
  return part;
}

PinholeFrame PinholeFrame::from_options(int width_px, int height_px, const PinholeFrameOptions& options,
                                        double default_focal_length_mm) {
  options.validate();
  if (options.horizontal_fov_deg) {
    const double half = 0.5 * rad_from_deg(*options.horizontal_fov_deg);
    return PinholeFrame(width_px, height_px, 0.5 * width_px / std::tan(half));
  }
  const double focal_mm = options.focal_length_mm.value_or(default_focal_length_mm);
  if (!(std::isfinite(focal_mm) && focal_mm > 0.0)) {
    throw OptionsError("pinhole focal length must be > 0 mm (got " + format_number(focal_mm) + ")");
  }
  const double pitch_mm = options.sensor_width_mm / width_px;
  return PinholeFrame(width_px, height_px, focal_mm / pitch_mm);
}

double PinholeFrame::horizontal_fov_deg() const { return deg_from_rad(2.0 * std::atan(0.5 * width_ / focal_px_)); }

std::string PinholeFrame::to_string() const {
  std::ostringstream os;
  os.precision(6);
  os << "PinholeFrame(" << width_ << " x " << height_ << " px, f = " << focal_px_ << " px, hfov "
     << horizontal_fov_deg() << " deg";
  if (centre_x_ != 0.5 * width_ || centre_y_ != 0.5 * height_) os << ", axis at (" << centre_x_ << ", " << centre_y_ << ") px";
  os << ")";
  return os.str();
}

}  // namespace lensmith

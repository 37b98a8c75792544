// A camera for the bokeh renderer: a lens (a real prescription or an ideal thin lens) at an
// f-number, focused on a plane by moving the sensor (unit focusing, as a real lens does), and the
// framing that maps sensor points back to the pixels of the all-in-focus (pinhole) input image.
//
// Conventions (docs/bokeh.md):
// - Scene depth is planar, measured along the axis from the perspective centre: the entrance pupil
//   of the lens at the reference wavelength (the lens itself for a thin lens). Scene points are
//   given by the direction tangents of the pinhole image's pixels and their inverse depth.
// - The sensor sits at the paraxial image of the focus plane at the reference wavelength.
// - Output framing keeps points on the focus plane at their input pixels: an output pixel is the
//   sensor point divided by the focus plane's magnification and seen through the pinhole frame.
//   An anamorphic lens magnifies x and y differently (its x section's focal length is shorter by
//   the squeeze): x is divided by the x section's magnification, so the output grid is the input's,
//   desqueezed, and a sensor pixel is squeeze() times narrower than it is tall (docs/bokeh.md,
//   "Anamorphic lenses").
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "lensmith/camera/pinhole_frame.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_spectral_table.h"
#include "lensmith/prescription/prescription.h"

namespace lensmith {

struct CameraOptions {
  double focus_distance_m = 0.0;          // focus plane, metres from the perspective centre (> 0, may be +inf)
  std::optional<double> f_number;         // empty: the lens's own (a thin lens needs one)
  PinholeFrameOptions framing;            // sensor width / pinhole focal length (default: the lens EFL) / hfov
  double reference_wavelength_nm = kWavelengthD_nm;  // focus and framing are set at this wavelength
  void validate() const;                  // throws OptionsError naming the option
  std::string to_string() const;
};

// First-order data of the lens at one wavelength (z in mm, z = 0 at surface 1; thin lens: all 0).
struct FirstOrderSample {
  double wavelength_nm = 0.0;
  double efl_mm = 0.0;
  double z_front_principal_mm = 0.0;
  double z_rear_principal_mm = 0.0;
  double z_entrance_pupil_mm = 0.0;
  double z_exit_pupil_mm = 0.0;
  double entrance_pupil_radius_mm = 0.0;
  double exit_pupil_radius_mm = 0.0;
  std::string to_string() const;
};

// A point of the scene: the direction tangents of the line from the perspective centre through it
// (x right, y up) and its inverse planar depth (1/mm; 0 = infinitely far).
struct ScenePoint {
  double tan_x = 0.0;
  double tan_y = 0.0;
  double inverse_depth_per_mm = 0.0;
};

// The paraxial (Gaussian) image of a scene point at one wavelength: a point in the lens frame.
struct GaussianImage {
  double x_mm = 0.0;
  double y_mm = 0.0;
  double z_mm = 0.0;
};

class Camera {
 public:
  // An ideal thin lens of focal length f (mm) at f-number N; pupils and principal planes at z = 0.
  static Camera thin_lens(double focal_length_mm, const CameraOptions& options, int width_px, int height_px);
  // The thin lens that stands for `lens` (its EFL; its own f-number unless options give one), with
  // the camera of the real lens at the same options kept as real_lens(). Without one where the real
  // lens cannot be made so (a stop wider than its surface allows, a focus it cannot image).
  static Camera thin_lens_for(const Prescription& lens, const CameraOptions& options, int width_px, int height_px);
  // A real lens (materials resolved). Its first-order data is tabulated at 64 wavelengths from
  // 380 to 780 nm. Throws ComputationError for afocal lenses or a focus plane the lens cannot image,
  // OptionsError for an f-number whose stop would be wider than its surface can be (naming the
  // fastest f-number the stop allows).
  // Mirror lenses (an even number of mirrors: the image faces the scene's way) and anamorphic lenses
  // (coaxial toroids and biconics) are taken, for the exact model only (exact_model_only); tilted or
  // decentred systems and an odd number of mirrors are refused (not implemented yet).
  static Camera from_lens(const Prescription& lens, const CameraOptions& options, int width_px, int height_px);

  bool is_thin_lens() const { return !lens_; }
  // Why only the exact model can photograph through this lens (its mirrors, central obscurations or
  // surfaces that are not rotationally symmetric are beyond the other models); empty when every model can.
  const std::optional<std::string>& exact_model_only() const { return exact_model_only_; }
  // The same for a lens before a camera is made of it (the CLI's default model follows it).
  static std::optional<std::string> exact_model_only_for(const Prescription& lens);
  // The prescription at the chosen f-number (aperture spec and stop semi-diameter set to it); null
  // for a thin lens.
  const Prescription* lens() const { return lens_.get(); }
  // For the thin lens that stands for a prescription (thin_lens_for), that real lens's camera: the
  // renderer takes the real lens's brightness across the frame from it. Null otherwise.
  const Camera* real_lens() const { return real_lens_.get(); }
  const PinholeFrame& frame() const { return frame_; }
  const CameraOptions& options() const { return options_; }
  double f_number() const { return f_number_; }
  // The lens's own f-number (its prescription's aperture); the thin lens: f_number().
  double design_f_number() const { return design_f_number_; }
  // The f-number below which a clear aperture other than the stop starts to clip the axial beam
  // (first order, the focus plane's marginal ray): opened further, the lens's rims and not the iris
  // limit the light on the axis. 0 when no other clear aperture is given (and for the thin lens).
  double fastest_unclipped_f_number() const { return fastest_unclipped_f_number_; }
  double focus_distance_mm() const { return focus_mm_; }
  double reference_wavelength_nm() const { return reference_nm_; }
  double z_sensor_mm() const { return z_sensor_mm_; }
  double z_perspective_mm() const { return z_perspective_mm_; }  // entrance pupil at the reference wavelength
  // -1 when the exit pupil is an inverted image of the entrance pupil, else +1.
  double pupil_orientation() const { return pupil_orientation_; }
  // Lowest and highest tabulated wavelengths (nm).
  double min_wavelength_nm() const;
  double max_wavelength_nm() const;

  // First-order data at a wavelength (linear interpolation between the tabulated samples).
  FirstOrderSample first_order(double wavelength_nm) const;
  // Paraxial image of a scene point through first-order data `s` (air on both sides).
  GaussianImage gaussian_image(const ScenePoint& p, const FirstOrderSample& s) const;
  // Output pixel of a sensor point (mm, lens frame x/y).
  PixelPoint output_pixel(double x_mm, double y_mm) const {
    return {0.5 * frame_.width_px() + x_mm * px_per_sensor_mm_x_, 0.5 * frame_.height_px() - y_mm * px_per_sensor_mm_};
  }
  // The sensor point (mm, lens frame x/y) of an output pixel position: output_pixel's inverse.
  std::array<double, 2> sensor_point_mm(const PixelPoint& p) const {
    return {(p.x - 0.5 * frame_.width_px()) / px_per_sensor_mm_x_, (0.5 * frame_.height_px() - p.y) / px_per_sensor_mm_};
  }
  // Output pixels per sensor millimetre in y, signed (< 0: the real image is inverted and the output is
  // not); in x it is squeeze() times this.
  double px_per_sensor_mm() const { return px_per_sensor_mm_; }
  // The anamorphic squeeze: output pixels per sensor millimetre in x over those in y, the ratio of the
  // focus plane's magnifications in y and x (EFL_y / EFL_x for a lens focused at infinity). 1 for a
  // lens without toroidal or biconic surfaces.
  double squeeze() const { return px_per_sensor_mm_x_ / px_per_sensor_mm_; }
  // An anamorphic lens's x section at the reference wavelength (its focal length, principal planes and
  // pupils: an anamorphic front group puts its x entrance pupil elsewhere); empty for other lenses.
  const std::optional<FirstOrderSample>& x_section() const { return x_section_; }
  // The distance (mm from the perspective centre; +inf at or beyond infinity) of the plane an anamorphic
  // lens's x section images onto the sensor: the sensor focuses the y section, and moving it focuses the x
  // section, whose focal length is shorter, elsewhere (a real anamorphic focuses its cylinders with the
  // rest: not modelled). Empty for other lenses.
  std::optional<double> x_section_focus_distance_mm() const;
  // Signed diameter (output pixels) of the paraxial blur disc of an on-axis point at this inverse
  // depth, reference wavelength: > 0 nearer than the focus plane, < 0 beyond it.
  double signed_coc_px(double inverse_depth_per_mm) const;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const Camera& c) { return os << c.to_string(); }

 private:
  Camera(const PinholeFrame& frame) : frame_(frame) {}
  void finish();  // sensor, framing scale

  std::shared_ptr<const Prescription> lens_;
  std::shared_ptr<const Camera> real_lens_;
  PinholeFrame frame_;
  CameraOptions options_;
  double f_number_ = 0.0;
  double design_f_number_ = 0.0;
  double fastest_unclipped_f_number_ = 0.0;
  std::optional<std::string> exact_model_only_;
  double focus_mm_ = 0.0;
  double reference_nm_ = kWavelengthD_nm;
  std::vector<ParaxialSample> samples_;  // evenly spaced in wavelength (one for a thin lens)
  double z_sensor_mm_ = 0.0;
  double z_perspective_mm_ = 0.0;
  double pupil_orientation_ = 1.0;
  double px_per_sensor_mm_ = 0.0;
  double px_per_sensor_mm_x_ = 0.0;
  // The x section's first-order data at the reference wavelength, for an anamorphic lens only.
  std::optional<FirstOrderSample> x_section_;
  FirstOrderSample reference_first_order_{};  // first_order(reference_nm_), for signed_coc_px per pixel
};

}  // namespace lensmith

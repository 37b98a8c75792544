// The seam between lens and renderer (DESIGN.md): a ray model takes a scene point, points of the
// aperture (normalised pupil coordinates) and a wavelength, and says where each ray meets the
// sensor, or that it does not (vignetted, failed). The renderer does not know how.
//
//   thin      an ideal thin lens (Cycles' and pbrt's thin-lens camera)
//   paraxial  the real lens's first-order data per wavelength: principal planes, pupils, focal
//             length; rays from the exit pupil through the Gaussian image point (no aberrations)
//   seidel    Asberg's method (Marsicano 2023, sec. 3.10): the Gaussian image point plus Born &
//             Wolf's third-order aberration vector, the ray leaving the Gaussian reference sphere
//   poly      a polynomial fit of the lens (polynomial optics, lensmith fit): Newton-aimed at the
//             stop point from the scene point, then mapped to the sensor; clipped by the fitted
//             positions on the clear apertures
//   exact     each ray traced through the prescription from the scene point, aimed so it crosses
//             the aperture stop at the requested point: slow, the reference
#pragma once

#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <string_view>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/camera.h"
#include "lensmith/polyfit/lens_fit.h"

namespace lensmith {

enum class RayModelKind { Thin, Paraxial, Seidel, Poly, Exact };

// "thin", "paraxial", "seidel", "poly", "exact" (the --model spelling).
std::string_view to_string(RayModelKind kind);
// Throws OptionsError listing the choices.
RayModelKind parse_ray_model_kind(std::string_view text);

// Where a ray meets the sensor plane (mm, lens frame). ok = false when it does not get there; then
// `unclipped` says whether x, y still hold where it would land if no clear aperture stopped it (the
// exact model), so callers can place the edge of a vignetted beam between rays.
struct SensorHit {
  double x_mm = 0.0;
  double y_mm = 0.0;
  bool ok = false;
  bool unclipped = false;
};

class RayModel {
 public:
  virtual ~RayModel() = default;
  virtual RayModelKind kind() const = 0;
  // True when, for a fixed scene point and wavelength, the sensor point is an affine function of the
  // pupil point: the bokeh is then the aperture's outline mapped by one affine map.
  virtual bool affine_in_pupil() const = 0;
  // Sensor hits for `pupil` points (normalised: the unit circle is the aperture at the camera's
  // f-number; for the exact model, on the aperture stop) of one scene point at one wavelength.
  // `hits` has the size of `pupil`. Thread-safe; allocates nothing per call once warm.
  virtual void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                   std::span<SensorHit> hits) const = 0;
  const Camera& camera() const { return camera_; }
  virtual std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const RayModel& m) { return os << m.to_string(); }

 protected:
  explicit RayModel(Camera camera) : camera_(std::move(camera)) {}
  Camera camera_;
};

struct RayModelOptions {
  // Nearest scene depth the model must serve (m, > 0): the Seidel coefficients are tabulated from it
  // to infinity, evenly in inverse distance.
  double nearest_depth_m = 0.5;
  int seidel_distance_samples = 12;  // >= 2
  // poly: a fit of the camera's lens (LensFit::fit or LensFit::read); empty: fitted when the model is
  // made, with LensFitOptions{} (several seconds).
  std::shared_ptr<const LensFit> fit;
  void validate() const;             // throws OptionsError
};

// Thin needs a thin-lens camera; the others a camera made from a prescription. Throws OptionsError
// for a mismatch (poly: a fit of another lens, a stop wider than the fit's, a frame or wavelength
// range beyond it) and what the Seidel analysis or the fit throws.
std::unique_ptr<RayModel> make_ray_model(RayModelKind kind, const Camera& camera, const RayModelOptions& options = {});

}  // namespace lensmith

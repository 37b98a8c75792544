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

#include <limits>
#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

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
//
// `weight` is the ray's radiometric weight: the light it carries, per unit of normalised pupil
// area, relative to the rays of the on-axis point of the focus plane, whose mean over the unit
// pupil is 1. It is the étendue of the pixel's patch of scene through that part of the pupil: the
// patch's area seen from the perspective centre (cos theta of the pinhole framing) times the solid
// angle the pupil element subtends at the point (cos^3 theta for a distant point, more off axis where
// the real entrance pupil grows), so that a uniform surface falls off across the frame as the
// lens's relative illumination (cos^4-type) times its clear-aperture vignetting. The thin lens, the
// ideal camera of path tracers, has weight 1 everywhere.
//
// `clearance` is how far inside the tightest clear aperture the ray passes, as a fraction of that
// aperture's radius: min over the clipping surfaces of 1 - r / R, >= 0 when it passes (ok) and
// < 0 when it is stopped (then `unclipped` holds where it would land). Between two rays the edge
// of the beam lies, to first order, where the linear interpolation of their clearances is 0.
// Models that clip nothing give 1.
struct SensorHit {
  double x_mm = 0.0;
  double y_mm = 0.0;
  bool ok = false;
  bool unclipped = false;
  double weight = 1.0;
  double clearance = 1.0;
};

// The share of a pupil triangle that passes, to first order: where the linear interpolation of its
// corners' clearances is >= 0 (with one corner alone on its side of 0, the small triangle there has
// the share p^2 / ((p - q)(p - r)) of the area, by similar triangles along its two edges).
double passing_share(double clearance_a, double clearance_b, double clearance_c);

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
  // map() for pupil points the caller already knows to pass (inside clip_discs): where they land
  // and their weights; `ok` is set and `clearance` left at 1 without being computed. The default
  // calls map().
  virtual void map_passing(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                           std::span<SensorHit> hits) const {
    map(point, wavelength_nm, pupil, hits);
  }
  // First-order models' clear-aperture vignetting of one scene point: the pupil points that pass are
  // those inside every disc of `discs` (cleared first; none: nothing clips). Models that clip rays
  // by tracing them (exact, poly) report it through map()'s `ok` and `clearance` and leave this
  // empty. Thread-safe.
  virtual void clip_discs(const ScenePoint& /*point*/, std::vector<PupilDisc>& discs) const { discs.clear(); }
  const Camera& camera() const { return camera_; }
  // The polynomial fit the poly model maps through; null for the other models.
  virtual std::shared_ptr<const LensFit> fit() const { return nullptr; }
  // Rays map() could not aim at their pupil point since the model was made (exact, poly; 0 for the
  // first-order models, which need no aiming). Such a ray comes back as neither ok nor unclipped:
  // drawn as stopped, it is a failure of the model, not vignetting, and callers report it.
  virtual std::size_t unaimed_rays() const { return 0; }
  // The lowest clearance (SensorHit::clearance) down to which a stopped ray's landing holds, where it
  // would land without the clear apertures: the poly model's fit learnt rays within its clear
  // apertures enlarged by LensFitOptions::aperture_margin only, and beyond that its landings are
  // extrapolations (a stopped ray's dark view in the light field, 4-7 px from where the beam's other
  // rays land: docs/bokeh.md). The other models' hold everywhere (minus infinity).
  virtual double landing_clearance_limit() const { return -std::numeric_limits<double>::infinity(); }
  virtual std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const RayModel& m) { return os << m.to_string(); }

 protected:
  explicit RayModel(Camera camera) : camera_(std::move(camera)) {}
  Camera camera_;
};

// Where the seidel model's Born & Wolf coefficients come from, at each object distance and
// wavelength of its table.
//   fitted  the least-squares fit of the third-order aberration vector to the exact tracer's rays at
//           the camera's f-number, over the frame (opt-in until the faint colour arcs it leaves on
//           some in-focus texture are found, docs/bokeh.md): the best third-order description of the
//           real lens, higher orders included where they balance the third (a corrected double Gauss
//           at f/2: third-order sums predict 0.10 mm of transverse spherical aberration at the rim,
//           the real rays 0.04 mm of the opposite sign)
//   sums    Welford's Seidel sums, the truncation Asberg's method uses (default): right for the lens's
//           third-order part, too large wherever higher orders correct it
enum class SeidelCoefficients { Fitted, Sums };
std::string_view to_string(SeidelCoefficients source);
// Throws OptionsError listing the choices.
SeidelCoefficients parse_seidel_coefficients(std::string_view text);

struct RayModelOptions {
  // Nearest scene depth the model must serve (m, > 0): the Seidel coefficients are tabulated from it
  // to infinity, evenly in inverse distance.
  double nearest_depth_m = 0.5;
  int seidel_distance_samples = 12;  // >= 2
  // poly: a fit of the camera's lens (LensFit::fit or LensFit::read); empty: fitted when the model is
  // made, with LensFitOptions{} (several seconds).
  std::shared_ptr<const LensFit> fit;
  // seidel: fitted to the exact tracer's rays (about 0.1 s more), or the Seidel sums (Asberg's
  // method as published).
  SeidelCoefficients seidel_coefficients = SeidelCoefficients::Fitted;
  void validate() const;             // throws OptionsError
};

// The options of a fit that serves `camera` (a prescription camera): its f-number, and a sensor
// radius covering its frame with the default's 15 % margin (at least the default's), so that a fit
// made for a render covers what is rendered.
LensFitOptions lens_fit_options_for(const Camera& camera);
// Throws OptionsError, with the reason and naming --model exact, when the poly model cannot take the
// camera's lens (LensFit::why_not_fittable: mirrors, tilts, decentres; a central obscuration): callers
// that fit before making the model check first.
void require_poly_model_lens(const Camera& camera);

// The output area (px^2) that one input pixel about pixel point `at` (input px: the camera's
// pinhole frame) images to at this inverse depth (1/mm): the determinant of the map from input to
// output pixels that the chief rays (pupil centre, reference wavelength) of `at` and of the points
// `step_px` to its right and below span (distortion, focus breathing). Where a lens compresses the
// picture (barrel distortion) an output pixel takes in more of the scene and its irradiance is
// higher by as much: the renderers weigh their footprints by it against the frame centre's. 0 where
// a chief ray lands nowhere.
double chief_ray_image_area(const RayModel& model, const PixelPoint& at, double inverse_depth_per_mm, double step_px = 1.0);

// Thin needs a thin-lens camera; the others a camera made from a prescription. Throws OptionsError
// for a mismatch (poly: a fit of another lens, a stop wider than the fit's, a frame or wavelength
// range beyond it) and what the Seidel analysis or the fit throws.
std::unique_ptr<RayModel> make_ray_model(RayModelKind kind, const Camera& camera, const RayModelOptions& options = {});

}  // namespace lensmith

// A polynomial fit of a real lens ("polynomial optics": Hullin, Hanika & Heidrich 2012; Hanika &
// Dachsbacher 2014; Schrade, Hanika & Dachsbacher 2016), fitted to rays of the exact tracer.
//
// Two reference planes, both in air:
//   sensor plane  z = sensor_plane_z_mm(), the paraxial focus of the lens (primary wavelength, the
//                 prescription's object distance); a camera that focuses elsewhere moves its sensor
//                 and carries the rays there in a straight line, which is exact in air;
//   outer pupil   surface 1 itself: a ray is taken where it meets the front surface (as Schrade et
//                 al. 2016 take the outer pupil on the front element). A plane in front of the lens
//                 would do for most lenses but not for fisheyes, whose object-side rays run nearly
//                 parallel to any such plane.
// A ray there is PlaneRay: its x, y where it crosses the plane or the front surface (mm; z follows
// from the surface's sag) and the x, y components of its unit direction taken along the light's
// travel toward the image (+z), so the same four numbers describe the line whichever way it is traced.
//
// Maps, each a rotation-invariant polynomial (rotational_map.h: out = A p + B d with A, B polynomials
// in |p|^2, p.d, |d|^2 and the wavelength) or, for an anamorphic lens (cylinders, toroids, biconics on
// one axis: symmetric only under its two section mirrors), each output component its own polynomial in
// the monomials those mirrors allow (component_map.h), with its own greedily chosen term set:
//   sensor -> outer:  position and direction on the outer pupil;
//   sensor -> clip:   position on every clipping surface (the stop first), from the sensor ray;
//   outer -> sensor:  position and direction on the sensor plane;
//   outer -> clip:    position on the same clipping surfaces, from the outer ray;
//   transmittance:    the uncoated Fresnel transmittance of the sensor ray (a scalar map).
// The ray maps and the clipping maps have separate term sets so the hot path (a ray from one plane
// to the other) pays only for its own outputs.
// Clipping surfaces are the stop and every surface whose clear aperture cuts rays of the sampled
// beam; at run time a ray passes when its fitted position on each lies within the semi-diameter (or
// passes the surface's explicit aperture: a mirror lens's central obscuration), so vignetting comes
// from the prescription's clear apertures, not from the polynomial's values.
// Mirror lenses fit as any other (the maps do not care how often the light turned on its way), as long
// as the image faces the way the light came from the scene: an even number of mirrors on one axis.
//
// Inputs are normalised to about [-1, 1] (positions by the largest training position, directions by
// the largest training direction, wavelength by the fitted range); the scales are part of the fit.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lensmith/polyfit/polynomial.h"
#include "lensmith/polyfit/fitted_map.h"
#include "lensmith/prescription/prescription.h"

namespace lensmith {

struct LensFitOptions {
  int degree = 7;              // highest total degree of a term, 1..kMaxPolyDegree
  // Term budget per output (shared by the outputs of a map), >= 1; 0 = automatic: 5 per surface less
  // 12, within 12..40. Why: the exact tracer costs about 24 ns per surface per ray and a fit about
  // 5 ns plus 0.4 ns per term (docs/performance.md), so this keeps a fit over 10 times faster than
  // tracing where both scale alike; short lenses, whose aberrations are simpler, need fewer terms.
  int terms = 0;
  int training_rays = 30000;   // rays the coefficients are fitted to, >= 200
  int test_rays = 10000;       // held-out rays (a different random stream) the errors are measured on, >= 100
  std::uint64_t seed = 2016;   // training stream; the test stream is derived from it
  double min_wavelength_nm = 380.0;
  double max_wavelength_nm = 780.0;
  // Radius (mm) on the sensor plane the fit covers. Empty: kDefaultImageRadiusMm, 1.15 x the
  // half-diagonal of a 36 x 24 mm frame, enough for a full-frame sensor refocused to about
  // f^2 / 10 mm behind the plane.
  std::optional<double> image_radius_mm;
  static constexpr double kFullFrameHalfDiagonalMm = 21.6333;
  static constexpr double kDefaultImageRadiusMm = 1.15 * kFullFrameHalfDiagonalMm;
  // Widest f-number the fit serves (a camera's iris opened beyond the prescription's stop); empty:
  // the lens's own. The fitted beam fills the stop at the wider of the two.
  std::optional<double> f_number;
  double pupil_margin = 1.15;     // sampled exit-pupil disc over the paraxial one (the real pupil is larger off axis)
  double aperture_margin = 1.05;  // training rays may pass clear apertures enlarged by this factor (a fit is
                                  // then good up to the edges the renderer clips at)
  void validate() const;          // throws OptionsError naming the option
  std::string to_string() const;
};

struct PlaneRay {
  double x_mm = 0.0;
  double y_mm = 0.0;
  double dx = 0.0;  // x component of the unit direction of travel (toward +z)
  double dy = 0.0;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const PlaneRay& r) { return os << r.to_string(); }
};

// A surface whose clear aperture clips rays of the fitted beam.
struct ClipSurface {
  int surface = 0;               // 1-based
  double semi_diameter_mm = 0.0; // the prescription's (for the stop: its wide-open radius)
  // The surface's explicit aperture (a mirror lens's central obscuration, an annulus, a rectangle),
  // which clips instead of the circle of semi_diameter_mm, as the exact tracer's does; empty = the
  // circle. Never set for the stop (a camera opens it as a circle).
  std::optional<SurfaceAperture> aperture;
  // How far inside what passes a crossing at (x, y) (mm) lies (SurfaceAperture::clearance; 1 - r / R
  // for the circle of radius `radius_mm`, the semi-diameter unless given): < 0 where it is stopped.
  double clearance(double x_mm, double y_mm, std::optional<double> radius_mm = std::nullopt) const {
    if (aperture) return aperture->clearance(x_mm, y_mm);
    // Not std::hypot: lens coordinates cannot overflow its square, and glibc's hypot was 8 % of an
    // exact-model render (every aimed ray checks every clear aperture).
    return 1.0 - std::sqrt(x_mm * x_mm + y_mm * y_mm) / radius_mm.value_or(semi_diameter_mm);
  }
  friend bool operator==(const ClipSurface&, const ClipSurface&) = default;
};

// Held-out errors of a fit, measured against the exact tracer on the test rays that pass the lens.
// Position and direction errors are lengths of the 2-D error vectors (not per component).
struct LensFitErrors {
  int test_rays = 0;                   // passing test rays the errors are taken over
  double position_rms_um = 0.0;        // sensor -> outer: position on the outer pupil (surface 1)
  double position_p99_um = 0.0;
  double direction_rms_mrad = 0.0;     // sensor -> outer: direction (1e-3 of a unit direction component)
  double stop_rms_um = 0.0;            // sensor -> outer: position on the stop
  double transmittance_rms = 0.0;      // absolute, transmittance in [0, 1]
  double sensor_position_rms_um = 0.0; // outer -> sensor: position on the sensor plane
  double sensor_position_p99_um = 0.0;
  double sensor_direction_rms_mrad = 0.0;
  // Fraction of held-out rays (passing or clipped within the sampled beam) whose pass / clip verdict
  // from the fitted clipping positions differs from the exact tracer's.
  double vignetting_mismatch = 0.0;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const LensFitErrors& e) { return os << e.to_string(); }
};

// How long the fit took to make, and (LensFit::measure_speed, on request: a fit made for a render does
// not spend time on it) the cost per ray on one thread from the sensor to the outer pupil of the exact
// tracer's batch path (unclipped) and of the fit's batch evaluation (LensFit::outer_rays, no
// clipping), on the same rays, median of 5 runs; 0 when not measured.
struct LensFitTiming {
  double fit_seconds = 0.0;  // sampling, term selection and coefficients, all threads
  double exact_ns_per_ray = 0.0;
  double poly_ns_per_ray = 0.0;
  bool speed_measured() const { return exact_ns_per_ray > 0.0 && poly_ns_per_ray > 0.0; }
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const LensFitTiming& t) { return os << t.to_string(); }
};

// Where a fitted ray goes: the ray on the far plane, where it crosses the stop, and whether every
// clipping surface lets it through.
struct FitTrace {
  PlaneRay ray;
  double stop_x_mm = 0.0;
  double stop_y_mm = 0.0;
  bool passes = false;
  // min over the clipping surfaces of 1 - r / R (r the fitted radius of the crossing, R the clear
  // semi-diameter, the stop's as clipped): >= 0 where the ray passes every one of them.
  double clearance = 1.0;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const FitTrace& t) { return os << t.to_string(); }
};

// A point of the scene for aiming from the object side: the direction tangents from an on-axis
// origin at z = origin_z_mm (lens frame) and the inverse of its planar depth from there (1/mm; 0 =
// infinitely far). The point is (tan_x / w, tan_y / w, origin_z_mm - 1 / w).
struct ObjectPoint {
  double tan_x = 0.0;
  double tan_y = 0.0;
  double inverse_depth_per_mm = 0.0;
  double origin_z_mm = 0.0;
};

struct FitAimOptions {
  double tolerance_mm = 1e-6;  // accepted miss on the stop, mm (> 0)
  int max_iterations = 20;     // Newton steps (>= 1)
  void validate() const;       // throws OptionsError
};

// The result of a Newton aim: the ray that the fit sends through the requested stop point, the
// iterations used and the remaining miss on the stop. converged = false when the miss stayed above the
// tolerance (the ray is then the best found, for reference only) or the iteration left the fit's domain.
struct FitAim {
  PlaneRay ray;
  // d(stop x, stop y) / d(unknown 1, unknown 2) at `ray`, row-major: the unknowns are the direction
  // (dx, dy) for aim_from_sensor and the outer-pupil position (x, y, mm) for aim_from_object.
  std::array<double, 4> jacobian{};
  bool converged = false;
  int iterations = 0;
  double miss_mm = 0.0;
  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const FitAim& a) { return os << a.to_string(); }
};

// The symmetry a fit's maps are written for: rotational (the invariant form) or only the mirrors of the
// x-z and y-z planes (an anamorphic lens; the component form).
enum class LensSymmetry { kRotational, kSectionMirrors };
std::string_view to_string(LensSymmetry symmetry);  // "rotational", "section mirrors"

class LensFit {
 public:
  // Why `lens` cannot be fitted (empty: it can). A fit describes the lens's coaxial core (coaxial_core:
  // all of it, or a tilt-shift lens's elements between the coordinate breaks at its ends, which are
  // applied exactly where the fit is used); a break between elements (a fold, an element tilted inside)
  // and an odd number of mirrors (the image facing the scene) are not implemented. Standard, toroidal
  // and biconic surfaces, mirrors and explicit apertures (central obscurations) are fitted.
  static std::optional<std::string> why_not_fittable(const Prescription& lens);
  // The symmetry the maps of `lens` are written for (why_not_fittable must be empty).
  static LensSymmetry symmetry_of(const Prescription& lens);
  // The automatic term budget for a lens of `surfaces` surfaces (LensFitOptions::terms = 0); the
  // component form of a lens without rotational symmetry gets three times the invariant form's.
  static int automatic_term_budget(std::size_t surfaces, LensSymmetry symmetry = LensSymmetry::kRotational);
  // Traces training and test rays through `lens` (materials resolved) and fits every map. Reports
  // progress in [0, 1] when given. Throws OptionsError, FitError (too few rays pass the lens) and what
  // the tracer throws.
  static LensFit fit(const Prescription& lens, const LensFitOptions& options = {},
                     const std::function<void(double)>& progress = {});

  // Measures the fit's speed against the exact tracer through `lens` (the prescription it was made
  // from: OptionsError otherwise) on passing rays of its own stream, as many as the fit's test rays,
  // and records it in timing(). One thread each; the process's OpenMP settings are not changed.
  void measure_speed(const Prescription& lens);

  // Versioned JSON ("lensmith-fit", version 1). read() throws FileError with file:line:col for
  // malformed files; write() goes through a temporary file and a rename.
  static LensFit parse(std::string_view text, const std::string& file_name);
  static LensFit read(const std::string& path);
  std::string to_json() const;
  void write(const std::string& path) const;

  // 16 hex digits identifying what the rays see of a prescription's coaxial core (the whole lens but a
  // tilt-shift lens's breaks at its ends: one fit serves every tilt and shift of the same elements):
  // every surface's shape, spacing, clear aperture (the stop's excepted: an f-number changes it),
  // mirrors, explicit apertures and index at 380, 587.56 and 780 nm.
  static std::string prescription_hash(const Prescription& lens);
  // Throws OptionsError when `lens` is not the prescription this fit was made from.
  void check_matches(const Prescription& lens) const;

  const std::string& lens_name() const { return lens_name_; }
  const std::string& lens_hash() const { return lens_hash_; }
  const LensFitOptions& options() const { return options_; }
  int term_budget() const { return term_budget_; }  // the budget used (options().terms or the automatic one)
  double sensor_plane_z_mm() const { return sensor_z_mm_; }
  double image_radius_mm() const { return image_radius_mm_; }
  int stop_surface() const { return clip_.front().surface; }
  double stop_radius_mm() const { return clip_.front().semi_diameter_mm; }  // wide open
  const std::vector<ClipSurface>& clip_surfaces() const { return clip_; }
  const LensFitErrors& errors() const { return errors_; }
  const LensFitTiming& timing() const { return timing_; }
  LensSymmetry symmetry() const { return symmetry_; }
  const FittedMap& sensor_to_outer() const { return sensor_to_outer_; }
  const FittedMap& sensor_to_clip() const { return sensor_clip_; }
  const FittedMap& outer_to_sensor() const { return outer_to_sensor_; }
  const FittedMap& outer_to_clip() const { return outer_clip_; }
  const FittedMap& transmittance_map() const { return transmittance_; }

  // Evaluation. `stop_radius_mm` is the stop's radius to clip at (a camera's f-number), at most the
  // fit's; empty: stop_radius_mm(). Thread-safe, allocation-free.
  FitTrace from_sensor(const PlaneRay& sensor, double wavelength_nm, std::optional<double> stop_radius_mm = {}) const;
  FitTrace from_outer(const PlaneRay& outer, double wavelength_nm, std::optional<double> stop_radius_mm = {}) const;
  double transmittance(const PlaneRay& sensor, double wavelength_nm) const;
  // Batch, structure of arrays, sensor -> outer ray only (no clipping): the fast path that
  // LensFitTiming measures. All spans the same size.
  void outer_rays(std::span<const double> x_mm, std::span<const double> y_mm, std::span<const double> dx,
                  std::span<const double> dy, std::span<const double> wavelength_nm, std::span<double> out_x_mm,
                  std::span<double> out_y_mm, std::span<double> out_dx, std::span<double> out_dy) const;

  // Newton on the sensor -> clip map: the direction from sensor point (x, y) whose fitted ray crosses
  // the stop at (stop_x, stop_y) (mm). The first guess aims at the paraxial exit-pupil image of the stop point.
  FitAim aim_from_sensor(double x_mm, double y_mm, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                         const FitAimOptions& options = {}) const;
  // Newton on the outer -> clip map: the outer-pupil ray from `object` whose fitted path crosses the
  // stop at (stop_x, stop_y). `guess` is a first outer-pupil position (x, y in mm); empty: the paraxial
  // entrance-pupil image of the stop point, and where Newton fails from there, the point's direction
  // approached from the axis in steps (continuation along the field).
  FitAim aim_from_object(const ObjectPoint& object, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                         std::optional<std::array<double, 2>> guess = {}, const FitAimOptions& options = {}) const;
  // The ray from `object` to the point of the front surface above (x, y) (mm), as the outer maps take
  // it; empty when the object point is not in front of that point or (x, y) is off the surface.
  std::optional<PlaneRay> outer_ray_from_object(const ObjectPoint& object, double x_mm, double y_mm) const;
  // Where the fitted outer ray through (x, y) (mm) from `object` crosses the stop (mm); empty
  // when that ray lies outside the fit's domain. The residual of aim_from_object, for callers that
  // iterate with a Jacobian of their own (a chord method across a pupil).
  std::optional<std::array<double, 2>> stop_from_object(const ObjectPoint& object, double x_mm, double y_mm,
                                                        double wavelength_nm) const;
  // The outer-pupil position (x, y, mm; where it crosses the plane of surface 1's vertex) of the paraxial ray from `object` through the entrance-pupil
  // image of a stop point, at the primary wavelength: the first guess of aim_from_object.
  std::array<double, 2> paraxial_outer_position(const ObjectPoint& object, double stop_x_mm, double stop_y_mm) const;

  std::string to_string() const;
  friend std::ostream& operator<<(std::ostream& os, const LensFit& f) { return os << f.to_string(); }

  // Normalisation of the polynomial inputs (part of the fit and its file).
  struct Scales {
    double sensor_position_mm = 1.0;
    double sensor_direction = 1.0;
    double outer_position_mm = 1.0;
    double outer_direction = 1.0;
    double wavelength_centre_nm = 580.0;
    double wavelength_half_range_nm = 200.0;
    friend bool operator==(const Scales&, const Scales&) = default;
  };
  // First-order data at the primary wavelength, for first guesses: pupils() in the y section,
  // pupils_x() in the x section (the same numbers for a rotationally symmetric lens; an anamorphic
  // front group puts the x section's entrance pupil far from the y section's).
  struct Pupils {
    double z_entrance_pupil_mm = 0.0;
    double entrance_per_stop = 1.0;  // entrance-pupil radius over stop radius, signed (< 0: inverted image)
    double z_exit_pupil_mm = 0.0;
    double exit_per_stop = 1.0;
    friend bool operator==(const Pupils&, const Pupils&) = default;
  };
  const Scales& scales() const { return scales_; }
  const Pupils& pupils() const { return pupils_; }
  const Pupils& pupils_x() const { return pupils_x_; }
  // The shape of surface 1 (the outer pupil), as in Surface: a standard conic with even asphere, or a
  // toroid or biconic (y section: curvature, conic, asphere; x section: curvature_x_per_mm, conic_x).
  struct FrontSurface {
    SurfaceKind kind = SurfaceKind::Standard;
    double curvature_per_mm = 0.0;
    double conic = 0.0;
    std::array<double, 8> even_asphere{};  // a2 .. a16 as in Surface
    double curvature_x_per_mm = 0.0;
    double conic_x = 0.0;
    friend bool operator==(const FrontSurface&, const FrontSurface&) = default;
  };
  const FrontSurface& front_surface() const { return front_; }
  // Sag of the front surface at (x, y) (mm): its z (mm, from its vertex) and dz/dx, dz/dy; empty
  // outside the shape's domain (Surface::sag_and_slope).
  std::optional<double> front_sag(double x_mm, double y_mm, double& dz_dx, double& dz_dy) const;

 private:
  // aim_from_object's Newton from outer-pupil position `start` (mm).
  FitAim aim_from_object_at(const ObjectPoint& object, double stop_x_mm, double stop_y_mm, double wavelength_nm,
                            const std::array<double, 2>& start, const FitAimOptions& options) const;
  LensFit() = default;
  void set_front_surface(const FrontSurface& front);  // front_ and front_shape_
  // outer_ray_from_object's ray with the derivatives of its direction in the surface point's x, y.
  struct OuterLine {
    PlaneRay ray;
    double ddx_dx, ddy_dx, ddx_dy, ddy_dy;
  };
  std::optional<OuterLine> outer_line(const ObjectPoint& object, double x_mm, double y_mm) const;
  double normalised_wavelength(double wavelength_nm) const {
    return (wavelength_nm - scales_.wavelength_centre_nm) / scales_.wavelength_half_range_nm;
  }
  FitTrace evaluate(const FittedMap& map, const FittedMap& clip, double position_scale, double direction_scale,
                    const PlaneRay& in, double wavelength_nm, std::optional<double> stop_radius_mm) const;

  std::string lens_name_;
  std::string lens_hash_;
  LensFitOptions options_;
  int term_budget_ = 0;
  double sensor_z_mm_ = 0.0;
  double image_radius_mm_ = 0.0;
  std::vector<ClipSurface> clip_;
  Scales scales_;
  Pupils pupils_;
  Pupils pupils_x_;
  FrontSurface front_;
  Surface front_shape_;  // front_ as a Surface, for its sag
  LensSymmetry symmetry_ = LensSymmetry::kRotational;
  FittedMap sensor_to_outer_;  // outputs: position, direction on the outer pupil
  FittedMap sensor_clip_;      // outputs: position on each clip surface
  FittedMap outer_to_sensor_;  // outputs: position, direction on the sensor plane
  FittedMap outer_clip_;       // outputs: position on each clip surface
  FittedMap transmittance_;    // one scalar output
  LensFitErrors errors_;
  LensFitTiming timing_;
};

}  // namespace lensmith

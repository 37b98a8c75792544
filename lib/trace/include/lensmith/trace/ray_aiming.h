// Making rays the way lens designers specify them: a field point and normalised pupil coordinates
// (px, py) in the unit disc, either on the paraxial entrance pupil (Zemax without ray aiming) or
// aimed by iteration so the real ray crosses the stop at (px, py) times the stop radius.
#pragma once

#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "lensmith/paraxial/paraxial_system.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith {

// A field point. Angles follow conventions.h: a positive y angle gives a chief ray with positive
// object-space slope (a positive lens images it at positive y, as ParaxialSystem's chief-ray table shows).
struct FieldPoint {
  enum class Kind {
    AngleDeg,        // x_angle_deg, y_angle_deg: direction (tan x, tan y, 1) normalised; object at infinity
                     // (for a finite object: the object-plane point on the chief ray at that angle)
    ObjectHeightMm,  // x, y object height at the prescription's (finite) object plane: the object point is
                     // at (x, y), as in Zemax (its chief ray falls; the image of a real lens lands at -y)
    ObjectPoint,     // an explicit object point in the global frame (mm), any z before surface 1
  };
  Kind kind = Kind::AngleDeg;
  double x = 0.0;
  double y = 0.0;
  Eigen::Vector3d point_mm{0.0, 0.0, 0.0};  // ObjectPoint only

  // point_mm is zeroed explicitly: `{}` here would call Eigen's default constructor, which leaves the vector
  // uninitialised, instead of the member initialiser above.
  static FieldPoint angle_deg(double y_deg, double x_deg = 0.0) {
    return {Kind::AngleDeg, x_deg, y_deg, Eigen::Vector3d::Zero()};
  }
  static FieldPoint object_height_mm(double y_mm, double x_mm = 0.0) {
    return {Kind::ObjectHeightMm, x_mm, y_mm, Eigen::Vector3d::Zero()};
  }
  static FieldPoint object_point_mm(const Eigen::Vector3d& p) { return {Kind::ObjectPoint, 0.0, 0.0, p}; }
  std::string to_string() const;
};

struct PupilCoordinate {
  double px = 0.0;  // normalised, x
  double py = 0.0;  // normalised, y (the tangential direction for a y field)
};

// RayAiming (paraxial entrance pupil or real stop) is in lensmith/prescription/prescription.h: a lens file sets it.

struct AimOptions {
  RayAiming aiming = RayAiming::ParaxialEntrancePupil;
  // RealStop: accepted miss (mm) of the returned ray on the stop surface, checked by a forward trace. The
  // backward solve that finds the ray (docs/trace.md, "Real-stop aiming") has its own angular tolerance; only
  // this forward miss decides whether a ray is returned.
  double tolerance_mm = 1e-10;
  // RealStop: Newton iterations one ray may use over all its solves (direct attempt, continuation steps, forward
  // check); NotConverged when they run out (>= 1).
  int max_iterations = 50;
  // Sample each field's vignetted pupil when the lens's field carries vignetting factors
  // (FieldSpec::vignetting, OpticStudio's VDX/VDY/VCX/VCY/VAN): (px, py) then mean the ray at
  // (vdx + px (1 - vcx), vdy + py (1 - vcy)) in the field's frame. Off: the whole pupil.
  bool use_vignetting_factors = true;
  void validate() const;  // throws OptionsError
};

// The result of making a ray: the ray in object space, starting a little before surface 1 (or at
// the object point), or a status saying why it could not be aimed (then `ray` is the paraxial-pupil ray of
// the request, for reference only: it does not cross the stop at the requested point).
struct AimedRay {
  RayStatus status = RayStatus::Ok;  // NotConverged when real aiming failed, or the status of the dying trace
  int surface = 0;                   // where an aiming trace died (NotConverged: the stop), 0 when ok
  Ray ray;
  bool ok() const { return status == RayStatus::Ok; }
};

class RayAimer {
 public:
  // Uses the paraxial system at the primary wavelength for the pupil and the stop. The stop radius that
  // pupil coordinate 1 means under RealStop aiming is, as in OpticStudio, the stop's semi-diameter when
  // the aperture floats by it, and otherwise the height at which the real axial ray through the edge of
  // the paraxial entrance pupil crosses the stop (the beam the EPD, F/# or NA defines in object space).
  RayAimer(const SequentialTracer& tracer, const AimOptions& options = {});

  AimedRay make_ray(const FieldPoint& field, const PupilCoordinate& pupil, double wavelength_nm) const;
  // The field point at the prescription's maximum field scaled by `relative` (0 = on axis, 1 = full),
  // along +y.
  FieldPoint field_at(double relative) const;

  const ParaxialSystem& paraxial() const { return paraxial_; }
  const SequentialTracer& tracer() const { return tracer_; }
  // The stop radius (mm) that pupil coordinate 1 means under RealStop aiming (see the constructor).
  double stop_radius_mm() const { return stop_radius_mm_; }
  // The pupil coordinate `make_ray` really aims at for `pupil` at `field`: `pupil` itself unless the lens's
  // vignetting factors apply (AimOptions::use_vignetting_factors).
  PupilCoordinate vignetted_pupil(const FieldPoint& field, const PupilCoordinate& pupil) const;

 private:
  const SequentialTracer& tracer_;
  AimOptions options_;
  ParaxialSystem paraxial_;
  double stop_radius_mm_ = 0.0;
  // Implementation-defined members (ray_aiming.cpp).
  double front_z_mm_ = 0.0;      // front-most z of surface 1 within its clear aperture (<= 0)
  double beam_radius_mm_ = 0.0;  // radius used to place the start wavefront of an angle field before surface 1
  // RealStop only (null otherwise): the partial tracers to and from the stop, the paraxial map from object space
  // to the stop and the table of real chief rays that start each solve (ray_aiming.cpp).
  struct StopSolver;
  std::shared_ptr<const StopSolver> stop_solver_;
};

// A lens whose field is given as real image heights (FieldSpec::Kind::RealImageHeightMm, OpticStudio's
// field type 3) with each field point turned into the object-space angle (object at infinity) or
// object height (finite object) whose real chief ray, aimed as the lens asks (Prescription::ray_aiming),
// meets the image plane as prescribed at that height for the primary wavelength; other lenses come back
// unchanged. Heights are radial: the result's values are >= 0. The solve is a secant iteration from the
// paraxial estimate to 1e-9 mm (relative for heights above 1 mm). Throws ComputationError naming the
// height when no chief ray reaches it (beyond the lens's image circle).
Prescription resolve_real_image_height_field(const Prescription& lens);

}  // namespace lensmith

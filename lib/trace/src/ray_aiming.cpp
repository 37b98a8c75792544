// Rays from a field point and normalised pupil coordinates: aimed at the paraxial entrance pupil
// (Welford, Aberrations of Optical Systems, sec. 4.6; Zemax without ray aiming), or by Newton's method on
// the object-space aim point so the real ray crosses the stop at the requested point (Zemax "real" ray
// aiming), with a finite-difference Jacobian. Where the rays start: docs/trace.md, "Ray aiming".
#include "lensmith/trace/ray_aiming.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

// Rays of an angle field start on a plane wavefront at least this far (mm) in front of the front-most
// point of surface 1, so a forward trace always starts in object space.
constexpr double kStartMargin_mm = 1.0;
// Samples of surface 1's sag when looking for its front-most point (aspheres need not be monotonic).
constexpr int kFrontSamples = 64;
// Finite-difference step of the aiming Jacobian, relative to the pupil size: the stop hit is accurate
// to ~1e-14 mm, so the derivative is good to ~1e-8 and its truncation error to ~1e-6, enough for Newton
// to gain six digits per iteration.
constexpr double kJacobianRelativeStep = 1e-6;
// A Newton step that kills the trace or increases the miss is halved at most this many times.
constexpr int kMaxStepHalvings = 12;
// Field continuation when the paraxial guess dies: steps of at most a quarter of the field, halved on
// failure down to 1/1024 of it.
constexpr double kFirstContinuationStep = 0.25;
constexpr double kMinContinuationStep = 1.0 / 1024.0;

// The sag of a surface at radius r (conic + even asphere); false outside its domain.
bool surface_sag(const Surface& s, double r_mm, double& sag_mm) {
  const double c = s.curvature_per_mm;
  const double u = r_mm * r_mm;
  const double d = 1.0 - (1.0 + s.conic) * c * c * u;
  if (d < 0.0) return false;
  double poly = 0.0;
  for (std::size_t j = s.even_asphere.size(); j-- > 0;) poly = poly * u + s.even_asphere[j];
  sag_mm = c * u / (1.0 + std::sqrt(d)) + u * poly;
  return std::isfinite(sag_mm);
}

// How the rays of one field point are made: a parallel beam (object at infinity) whose rays start on
// one plane wavefront, or rays from an object point.
struct Beam {
  bool parallel = true;
  Eigen::Vector3d direction{0.0, 0.0, 1.0};  // parallel: unit direction of every ray
  double wavefront_distance_mm = 0.0;        // parallel: the start plane lies this far before the EP centre
  Eigen::Vector3d origin{0.0, 0.0, 0.0};     // finite: the object point
};

// The ray of `beam` that crosses the entrance-pupil plane z_ep at (qx, qy). False when no such ray exists
// (the object point lies on the pupil plane at that point).
bool ray_through(const Beam& beam, double qx, double qy, double z_ep_mm, double wavelength_nm, Ray& ray) {
  const Eigen::Vector3d q(qx, qy, z_ep_mm);
  ray.wavelength_nm = wavelength_nm;
  if (beam.parallel) {
    // Start where the line through q meets the plane normal to d at distance L before the EP centre c:
    // (q + t d - (c - L d)).d = 0  =>  t = (c - q).d - L.
    const Eigen::Vector3d& d = beam.direction;
    const double t = -(qx * d.x() + qy * d.y()) - beam.wavefront_distance_mm;
    ray.position_mm = q + t * d;
    ray.direction = d;
    return true;
  }
  const Eigen::Vector3d to_pupil = q - beam.origin;
  const double length = to_pupil.norm();
  if (!(length > 0.0) || !std::isfinite(length)) return false;
  ray.position_mm = beam.origin;
  ray.direction = to_pupil / length;
  return true;
}

}  // namespace

void AimOptions::validate() const {
  if (!(std::isfinite(tolerance_mm) && tolerance_mm > 0.0)) {
    std::ostringstream os;
    os << "AimOptions::tolerance_mm = " << tolerance_mm << ": must be finite and > 0";
    throw OptionsError(os.str());
  }
  if (max_iterations < 1) {
    throw OptionsError("AimOptions::max_iterations = " + std::to_string(max_iterations) + ": must be >= 1");
  }
}

std::string FieldPoint::to_string() const {
  std::ostringstream os;
  os.precision(10);
  switch (kind) {
    case Kind::AngleDeg: os << "field angle (x " << x << ", y " << y << ") deg"; break;
    case Kind::ObjectHeightMm: os << "object height (x " << x << ", y " << y << ") mm"; break;
    case Kind::ObjectPoint:
      os << "object point (" << point_mm.x() << ", " << point_mm.y() << ", " << point_mm.z() << ") mm";
      break;
  }
  return os.str();
}

RayAimer::RayAimer(const SequentialTracer& tracer, const AimOptions& options)
    : tracer_(tracer), options_(options), paraxial_(tracer.lens()) {
  options_.validate();
  const Prescription& lens = tracer_.lens();
  const int stop = paraxial_.stop_surface();
  // Pupil coordinate 1 is the edge of the beam the aperture specification defines (as in Zemax):
  // the paraxial marginal height at the stop. With an aperture that floats by the stop this is the
  // stop's semi-diameter; with an EPD or F/# it may be smaller than the stop's clear aperture.
  stop_radius_mm_ = std::abs(paraxial_.marginal_ray().rows[static_cast<std::size_t>(stop) - 1].y_mm);

  // The front-most point of surface 1 over its clear aperture (or twice the EP radius without one).
  const double ep_radius_mm = 0.5 * paraxial_.entrance_pupil().diameter_mm;
  const Surface& first = lens.surfaces.front();
  const double front_radius_mm = first.semi_diameter_mm.value_or(2.0 * ep_radius_mm);
  double lowest_sag_mm = 0.0;
  for (int i = 1; i <= kFrontSamples; ++i) {
    double sag_mm = 0.0;
    if (surface_sag(first, front_radius_mm * i / kFrontSamples, sag_mm)) lowest_sag_mm = std::min(lowest_sag_mm, sag_mm);
  }
  front_z_mm_ = tracer_.vertex_z_mm(1) + lowest_sag_mm;
  beam_radius_mm_ = std::max(ep_radius_mm, front_radius_mm);

  // RealStop traces only to the stop and ignores clear apertures: an intermediate guess may pass outside
  // a rim that the converged ray clears (Zemax's ray aiming does the same).
  Prescription to_stop = lens;
  to_stop.surfaces.resize(static_cast<std::size_t>(stop));
  to_stop.surfaces.back().thickness_mm = 0.0;
  to_stop.image_at_paraxial_focus = false;
  TracerOptions unclipped;
  unclipped.clip_apertures = false;
  unclipped.image_distance_mm = 0.0;
  to_stop_ = std::make_shared<const SequentialTracer>(to_stop, unclipped);
}

FieldPoint RayAimer::field_at(double relative) const {
  const Prescription& lens = tracer_.lens();
  const bool at_infinity = std::isinf(paraxial_.object_distance_mm());
  if (!lens.field) {
    if (relative == 0.0) return at_infinity ? FieldPoint::angle_deg(0.0) : FieldPoint::object_height_mm(0.0);
    throw ComputationError("field_at(" + std::to_string(relative) + "): the prescription has no field");
  }
  const double max_value = lens.field->max_value();
  switch (lens.field->kind) {
    case FieldSpec::Kind::AngleDeg: return FieldPoint::angle_deg(relative * max_value);
    case FieldSpec::Kind::ObjectHeightMm: return FieldPoint::object_height_mm(relative * max_value);
    case FieldSpec::Kind::ImageHeightMm: {
      // The paraxial chief ray of the maximum field lands at the maximum image height; chief rays are linear
      // in their object-space slope, so a fraction of the image height is the same fraction of the slope.
      const ParaxialRayTable& chief = *paraxial_.chief_ray();
      const double slope = relative * chief.object_slope;
      if (at_infinity) return FieldPoint::angle_deg(deg_from_rad(std::atan(slope)));
      // An object-height field h puts the object point at y = -h (conventions.h), on the chief ray.
      return FieldPoint::object_height_mm(slope * (paraxial_.object_distance_mm() + paraxial_.entrance_pupil().z_mm));
    }
  }
  return FieldPoint::angle_deg(0.0);
}

AimedRay RayAimer::make_ray(const FieldPoint& field, const PupilCoordinate& pupil, double wavelength_nm) const {
  AimedRay out;
  out.ray.wavelength_nm = wavelength_nm;
  const bool finite_inputs = std::isfinite(field.x) && std::isfinite(field.y) &&
                             (field.kind != FieldPoint::Kind::ObjectPoint || field.point_mm.allFinite()) &&
                             std::isfinite(pupil.px) && std::isfinite(pupil.py) && std::isfinite(wavelength_nm) &&
                             wavelength_nm > 0.0;
  if (!finite_inputs) {
    out.status = RayStatus::InvalidInput;
    return out;
  }

  const double z_ep = paraxial_.entrance_pupil().z_mm;
  const double ep_radius = 0.5 * paraxial_.entrance_pupil().diameter_mm;
  const double object_distance = paraxial_.object_distance_mm();
  const double z_object = -object_distance;

  if (field.kind == FieldPoint::Kind::AngleDeg && !(std::abs(field.x) < 90.0 && std::abs(field.y) < 90.0)) {
    out.status = RayStatus::InvalidInput;
    return out;
  }
  if (field.kind == FieldPoint::Kind::ObjectHeightMm && std::isinf(object_distance)) {
    throw OptionsError("FieldPoint " + field.to_string() +
                       ": an object-height field needs a finite object distance (the object is at infinity)");
  }
  // The beam of the field scaled by `fraction` (1 = the field asked for; smaller values serve the field
  // continuation of RealStop aiming below).
  auto make_beam = [&](double fraction) {
    Beam beam;
    switch (field.kind) {
      case FieldPoint::Kind::AngleDeg: {
        const Eigen::Vector3d d = Eigen::Vector3d(std::tan(rad_from_deg(fraction * field.x)),
                                                  std::tan(rad_from_deg(fraction * field.y)), 1.0)
                                      .normalized();
        if (std::isinf(object_distance)) {
          beam.parallel = true;
          beam.direction = d;
          // Far enough that a ray within beam_radius_mm_ of the chief ray starts kStartMargin_mm before the
          // front of surface 1: its start z is at most z_ep + d_z (rho sin(theta) - L).
          const double sin_theta = std::hypot(d.x(), d.y());
          beam.wavefront_distance_mm = beam_radius_mm_ * sin_theta + (z_ep - front_z_mm_ + kStartMargin_mm) / d.z();
        } else {
          // A finite object: the object point is where the chief ray at this angle, through the EP centre,
          // meets the object plane.
          beam.parallel = false;
          beam.origin = Eigen::Vector3d(0.0, 0.0, z_ep) + d * ((z_object - z_ep) / d.z());
        }
        break;
      }
      case FieldPoint::Kind::ObjectHeightMm:
        // Object point at -h so that the chief ray rises like that of a positive angle (conventions.h).
        beam.parallel = false;
        beam.origin = Eigen::Vector3d(-fraction * field.x, -fraction * field.y, z_object);
        break;
      case FieldPoint::Kind::ObjectPoint:
        beam.parallel = false;
        beam.origin = Eigen::Vector3d(fraction * field.point_mm.x(), fraction * field.point_mm.y(), field.point_mm.z());
        break;
    }
    return beam;
  };
  const Beam beam = make_beam(1.0);

  if (options_.aiming == RayAiming::ParaxialEntrancePupil) {
    if (!ray_through(beam, pupil.px * ep_radius, pupil.py * ep_radius, z_ep, wavelength_nm, out.ray)) {
      out.status = RayStatus::InvalidInput;
    }
    return out;
  }

  // RealStop: find the EP-plane point q whose real ray meets the stop at the target.
  const int stop = paraxial_.stop_surface();
  const std::size_t stop_index = static_cast<std::size_t>(stop) - 1;
  const Eigen::Vector2d target(pupil.px * stop_radius_mm_, pupil.py * stop_radius_mm_);
  std::vector<SurfaceHit> path;
  path.reserve(static_cast<std::size_t>(stop));
  RayStatus dead_status = RayStatus::Ok;
  int dead_surface = 0;
  // The miss on the stop for the ray of `b` through q; false (with the status) when it does not reach the stop.
  auto miss = [&](const Beam& b, const Eigen::Vector2d& q, Eigen::Vector2d& residual) {
    Ray ray;
    if (!ray_through(b, q.x(), q.y(), z_ep, wavelength_nm, ray)) {
      dead_status = RayStatus::InvalidInput;
      dead_surface = 0;
      return false;
    }
    const TraceResult result = to_stop_->trace_forward(ray, &path);
    if (path.size() <= stop_index) {
      dead_status = result.status;
      dead_surface = result.surface;
      return false;
    }
    residual = Eigen::Vector2d(path[stop_index].point_mm.x(), path[stop_index].point_mm.y()) - target;
    return true;
  };

  // Damped Newton from q (updated in place), at most options_.max_iterations steps.
  enum class Outcome { Converged, Died, NotConverged };
  const double step = kJacobianRelativeStep * std::max(ep_radius, stop_radius_mm_);
  auto solve = [&](const Beam& b, Eigen::Vector2d& q) {
    Eigen::Vector2d residual;
    if (!miss(b, q, residual)) return Outcome::Died;
    if (residual.norm() <= options_.tolerance_mm) return Outcome::Converged;
    for (int iteration = 0; iteration < options_.max_iterations; ++iteration) {
      Eigen::Vector2d residual_x;
      Eigen::Vector2d residual_y;
      if (!miss(b, q + Eigen::Vector2d(step, 0.0), residual_x) || !miss(b, q + Eigen::Vector2d(0.0, step), residual_y)) {
        return Outcome::Died;
      }
      // Forward-difference Jacobian J = d(stop hit) / d(q); Newton step -J^-1 residual by Cramer's rule.
      const Eigen::Vector2d dx = (residual_x - residual) / step;
      const Eigen::Vector2d dy = (residual_y - residual) / step;
      const double determinant = dx.x() * dy.y() - dy.x() * dx.y();
      if (!(std::abs(determinant) > 0.0) || !std::isfinite(determinant)) return Outcome::NotConverged;
      const Eigen::Vector2d newton_step((dx.y() * residual.y() - dy.y() * residual.x()) / determinant,
                                        (dy.x() * residual.x() - dx.x() * residual.y()) / determinant);
      // Damped step: halve while the trace dies or the miss grows.
      double fraction = 1.0;
      bool moved = false;
      for (int halving = 0; halving <= kMaxStepHalvings; ++halving, fraction *= 0.5) {
        Eigen::Vector2d trial_residual;
        const Eigen::Vector2d trial = q + fraction * newton_step;
        if (!miss(b, trial, trial_residual)) continue;
        if (trial_residual.norm() < residual.norm() || halving == kMaxStepHalvings) {
          q = trial;
          residual = trial_residual;
          moved = true;
          break;
        }
      }
      if (!moved) return Outcome::Died;
      if (residual.norm() <= options_.tolerance_mm) return Outcome::Converged;
    }
    return Outcome::NotConverged;
  };

  auto finish = [&](RayStatus status, int surface, const Eigen::Vector2d& q) {
    out.status = status;
    out.surface = surface;
    if (!ray_through(beam, q.x(), q.y(), z_ep, wavelength_nm, out.ray)) out.status = RayStatus::InvalidInput;
    return out;
  };

  // Start from the paraxial image of the target in the entrance pupil (signed magnification).
  const Eigen::Vector2d paraxial_guess = paraxial_.entrance_pupil().magnification * target;
  Eigen::Vector2d q = paraxial_guess;
  const Outcome direct = solve(beam, q);
  if (direct == Outcome::Converged) return finish(RayStatus::Ok, 0, q);
  if (direct == Outcome::NotConverged) return finish(RayStatus::NotConverged, stop, q);

  // The paraxial guess is too far off for Newton (pupil aberration of wide-angle and fisheye lenses): follow
  // the solution from the axis out to the field in adaptive steps, each started from the last solution.
  const RayStatus first_status = dead_status;
  const int first_surface = dead_surface;
  Eigen::Vector2d followed = paraxial_guess;
  if (solve(make_beam(0.0), followed) != Outcome::Converged) return finish(first_status, first_surface, q);
  double reached = 0.0;
  double increment = kFirstContinuationStep;
  while (reached < 1.0) {
    const double next = std::min(1.0, reached + increment);
    Eigen::Vector2d trial = followed;
    if (solve(make_beam(next), trial) == Outcome::Converged) {
      followed = trial;
      reached = next;
      increment = std::min(2.0 * increment, kFirstContinuationStep);
    } else {
      increment *= 0.5;
      if (increment < kMinContinuationStep) return finish(first_status, first_surface, q);
    }
  }
  return finish(RayStatus::Ok, 0, followed);
}

}  // namespace lensmith

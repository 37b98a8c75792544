// Rays from a field point and normalised pupil coordinates: aimed at the paraxial entrance pupil (Welford,
// Aberrations of Optical Systems, sec. 4.6; Zemax without ray aiming), or at a point of the real stop (Zemax
// "robust" ray aiming). Real-stop aiming traces backward from the stop point and solves, by damped Newton with
// continuation in field and pupil (Allgower & Georg, Introduction to Numerical Continuation Methods, ch. 2),
// for the stop-space direction whose ray leaves surface 1 along the requested object-space ray; a forward
// Newton polish then puts the returned ray on the stop within the tolerance. Details: docs/trace.md, "Ray aiming".
#include "lensmith/trace/ray_aiming.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <Eigen/Geometry>  // cross product

#include "lensmith/core/errors.h"
#include "lensmith/core/root_solver_2d.h"
#include "lensmith/core/units.h"
#include "lensmith/prescription/lens_file.h"

namespace lensmith {

namespace {

// Rays of an angle field start on a plane wavefront at least this far (mm) in front of the front-most
// point of surface 1, so a forward trace always starts in object space.
constexpr double kStartMargin_mm = 1.0;
// Samples of surface 1's sag when looking for its front-most point (aspheres need not be monotonic).
constexpr int kFrontSamples = 64;

// Real-stop aiming. The backward solve's residual is the difference of two unit vectors (the object-space
// direction of the backward ray and the requested one), i.e. the angle between them in radians.
// Converged: a hundred times the rounding of a 20-surface trace (~1e-14), so the forward polish starts within
// ~1e-11 mm of the stop point and usually has nothing left to do.
constexpr double kBackwardTolerance_rad = 1e-12;
// A backward solve that stalls (rounding) this close still hands a usable start to the forward polish.
constexpr double kBackwardUsable_rad = 1e-8;
// Intermediate continuation steps only need to stay on the solution path.
constexpr double kTrackingTolerance_rad = 1e-8;
// Finite-difference step of the backward Jacobian in the stop-space tangent (~1): the residual is accurate to
// ~1e-14, so the derivative is good to ~1e-7 and Newton still gains seven digits per step.
constexpr double kTangentStep = 1e-7;
// A backward Newton step moves the stop-space tangent by at most this (~27 degrees near the axis): a trust
// region that keeps a nearly singular Jacobian from throwing the ray out of the lens.
constexpr double kMaxTangentStep = 0.5;
// Line search: Armijo's sufficient decrease on |residual|, at most this many halvings of the step.
constexpr double kArmijo = 1e-4;
constexpr int kMaxStepHalvings = 20;
// Finite-difference step of the forward polish, relative to the pupil size: the stop hit is accurate to ~1e-14 mm,
// so the derivative is good to ~1e-8, ample for the one step the polish usually needs, if any.
constexpr double kJacobianRelativeStep = 1e-6;
// A ray whose next crossing lies this far (mm) behind the previous one runs backward between two surfaces: the
// surfaces cross there (negative edge thickness), so no physical ray takes that path.
constexpr double kSegmentSlack_mm = 1e-9;
// Table of real chief rays from the stop centre (meridional plane, primary wavelength): stop-space angles
// 0..kChiefTableMaxDeg in steps of kChiefTableStepDeg; it ends where the backward trace dies or folds.
constexpr double kChiefTableStepDeg = 0.5;
constexpr double kChiefTableMaxDeg = 85.0;
// Continuation: first step, largest and smallest step of the path parameter (0..1). One solve (the direct
// attempt or one continuation step) that has not converged after kCorrectorIterations Newton iterations has
// failed: from a good start Newton needs 3 to 5.
constexpr double kFirstContinuationStep = 0.25;
constexpr double kMaxContinuationStep = 0.5;
constexpr double kMinContinuationStep = 1.0 / 1024.0;
constexpr int kCorrectorIterations = 12;

// The sag of a surface at radius r (Surface::sag_mm); false outside its domain.
bool surface_sag(const Surface& s, double r_mm, double& sag_mm) {
  sag_mm = s.sag_mm(r_mm);
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

// Where the beams of the field points start (fixed per aimer).
struct BeamGeometry {
  double z_ep_mm = 0.0;
  double object_distance_mm = kInfinity;
  double front_z_mm = 0.0;
  double beam_radius_mm = 0.0;
};

// The beam of `field` scaled by `fraction` (1 = the field asked for; smaller values serve the field
// continuation of RealStop aiming).
Beam beam_of(const FieldPoint& field, double fraction, const BeamGeometry& g) {
  Beam beam;
  const double z_object = -g.object_distance_mm;
  switch (field.kind) {
    case FieldPoint::Kind::AngleDeg: {
      const Eigen::Vector3d d = Eigen::Vector3d(std::tan(rad_from_deg(fraction * field.x)),
                                                std::tan(rad_from_deg(fraction * field.y)), 1.0)
                                    .normalized();
      if (std::isinf(g.object_distance_mm)) {
        beam.parallel = true;
        beam.direction = d;
        // Far enough that a ray within beam_radius_mm of the chief ray starts kStartMargin_mm before the
        // front of surface 1: its start z is at most z_ep + d_z (rho sin(theta) - L).
        const double sin_theta = std::hypot(d.x(), d.y());
        beam.wavefront_distance_mm =
            g.beam_radius_mm * sin_theta + (g.z_ep_mm - g.front_z_mm + kStartMargin_mm) / d.z();
      } else {
        // A finite object: the object point is where the chief ray at this angle, through the EP centre,
        // meets the object plane.
        beam.parallel = false;
        beam.origin = Eigen::Vector3d(0.0, 0.0, g.z_ep_mm) + d * ((z_object - g.z_ep_mm) / d.z());
      }
      break;
    }
    case FieldPoint::Kind::ObjectHeightMm:
      // The object point is at (x, y), as in Zemax's object-height fields.
      beam.parallel = false;
      beam.origin = Eigen::Vector3d(fraction * field.x, fraction * field.y, z_object);
      break;
    case FieldPoint::Kind::ObjectPoint:
      beam.parallel = false;
      beam.origin = Eigen::Vector3d(fraction * field.point_mm.x(), fraction * field.point_mm.y(), field.point_mm.z());
      break;
  }
  return beam;
}

// An orthonormal pair (u1, u2) perpendicular to the unit vector n.
void perpendicular_basis(const Eigen::Vector3d& n, Eigen::Vector3d& u1, Eigen::Vector3d& u2) {
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  u1 = (helper - helper.dot(n) * n).normalized();
  u2 = n.cross(u1);
}

// True when every refracting crossing of `path` lies ahead of the previous one along the ray (and, when `start` is
// given, the first ahead of the start point along `start_direction`); else `surface` is the first crossing that lies
// behind. Crossings of surfaces that do not refract (`refracts[k - 1]` false: a stop or dummy plane with the same
// medium on both sides) are skipped: a ray may meet such a plane "behind" the previous surface (a flat stop at the
// vertex of a convex surface) without leaving the straight line it is on.
bool runs_forward(const std::vector<SurfaceHit>& path, const std::vector<char>& refracts, int& surface,
                  const Eigen::Vector3d* start = nullptr, const Eigen::Vector3d* start_direction = nullptr) {
  const Eigen::Vector3d* from = start;
  const Eigen::Vector3d* along = start_direction;
  for (const SurfaceHit& hit : path) {
    if (!refracts[static_cast<std::size_t>(hit.surface) - 1]) continue;
    if (from && (hit.point_mm - *from).dot(*along) < -kSegmentSlack_mm) {
      surface = hit.surface;
      return false;
    }
    from = &hit.point_mm;
    along = &hit.direction_after;
  }
  return true;
}

}  // namespace

// Everything real-stop aiming precomputes: the partial tracers, the paraxial map and the chief-ray table.
struct RayAimer::StopSolver {
  // One aiming problem: the beam of a field point, the stop point its ray must cross and the frame in which
  // the object-space direction error is measured.
  struct Target {
    Beam beam;
    Eigen::Vector2d stop_xy{0.0, 0.0};
    Eigen::Vector3d stop_point_mm{0.0, 0.0, 0.0};  // on the stop surface
    Eigen::Vector3d nominal{0.0, 0.0, 1.0};        // close to the ray's object-space direction
    Eigen::Vector3d u1{1.0, 0.0, 0.0};             // perpendicular to nominal
    Eigen::Vector3d u2{0.0, 1.0, 0.0};
    bool valid = true;                             // false: the stop point lies outside the stop's sag domain
  };
  // The backward ray from the stop point with stop-space tangent v, in object space.
  struct Backward {
    RayStatus status = RayStatus::Ok;
    int surface = 0;
    Eigen::Vector2d residual{0.0, 0.0};   // (f - g).(u1, u2): f the ray's direction, g the requested one
    Eigen::Vector3d on_first{0.0, 0.0, 0.0};  // where it leaves surface 1 (the stop point when stop = 1)
    bool right_way = false;                   // f and g point along `nominal` (not each other's mirror image)
    bool alive() const { return status == RayStatus::Ok; }
  };
  // One real chief ray of the table: stop-space tangent and the object-space ray (meridional plane y-z).
  struct ChiefSample {
    double tangent = 0.0;
    double y1_mm = 0.0, z1_mm = 0.0;  // on surface 1
    double fy = 0.0, fz = 1.0;        // forward object-space direction
  };
  enum class Outcome { Converged, Died, Stalled, OutOfIterations };
  // The state of aiming one ray: its wavelength, a scratch path and the Newton iterations it has left
  // (AimOptions::max_iterations over all its solves).
  struct Work {
    double wavelength_nm = 0.0;
    std::vector<SurfaceHit> path;
    int iterations_left = 0;
  };

  StopSolver(const SequentialTracer& tracer, const ParaxialSystem& paraxial, double stop_radius_mm, double ep_radius_mm,
             const BeamGeometry& geometry, const AimOptions& options);

  AimedRay aim(const FieldPoint& field, const Eigen::Vector2d& stop_xy, double wavelength_nm) const;

  Target target(const Beam& beam, const Eigen::Vector2d& stop_xy) const;
  Eigen::Vector2d guess(const Target& t) const;
  Backward backward(const Target& t, const Eigen::Vector2d& v, Work& work) const;
  Outcome newton(const Target& t, Eigen::Vector2d& v, Backward& at_v, double tolerance, int max_iterations,
                 Work& work) const;
  template <typename TargetAt>
  bool follow(TargetAt target_at, Eigen::Vector2d& v, Backward& at_v, Work& work) const;
  bool polish(const Target& t, const Backward& solved, Ray& ray, Work& work) const;
  double signed_chief_tangent(const std::vector<double>& reach, double wanted) const;

  int stop = 0;
  AimOptions options;
  BeamGeometry geometry;
  double stop_radius_mm = 0.0;
  double ep_radius_mm = 0.0;
  Surface stop_surface;
  double stop_vertex_z_mm = 0.0;
  std::shared_ptr<const SequentialTracer> to_stop;      // surfaces 1..stop, apertures not clipped
  std::shared_ptr<const SequentialTracer> before_stop;  // surfaces 1..stop-1, apertures not clipped; null at stop 1
  // Paraxial map (primary wavelength) from (object-space slope u0, height y1 on the plane of vertex 1) to
  // (slope arriving at the stop, height at the stop).
  double m11 = 1.0, m12 = 0.0, m21 = 0.0, m22 = 1.0;
  std::vector<char> refracts;            // per surface 1..stop: the index changes across it (else a stop or dummy)
  std::vector<ChiefSample> chief;        // first branch of real chief rays (monotone field angle)
  std::vector<double> chief_angle_rad;   // their object-space angles atan(fy / fz)
};

RayAimer::StopSolver::StopSolver(const SequentialTracer& tracer, const ParaxialSystem& paraxial, double stop_radius,
                                 double ep_radius, const BeamGeometry& beam_geometry, const AimOptions& aim_options)
    : stop(paraxial.stop_surface()),
      options(aim_options),
      geometry(beam_geometry),
      stop_radius_mm(stop_radius),
      ep_radius_mm(ep_radius) {
  const Prescription& lens = tracer.lens();
  const std::size_t stop_index = static_cast<std::size_t>(stop) - 1;
  stop_surface = lens.surfaces[stop_index];
  stop_vertex_z_mm = tracer.vertex_z_mm(stop);
  // A surface refracts when the index changes across it at any of the F, d and C lines (a glass pair that happens
  // to match at one wavelength still refracts at the others).
  refracts.assign(static_cast<std::size_t>(stop), 0);
  for (int k = 1; k <= stop; ++k) {
    for (double w : {kWavelengthF_nm, kWavelengthD_nm, kWavelengthC_nm}) {
      if (tracer.index_after(k - 1, w) != tracer.index_after(k, w)) refracts[static_cast<std::size_t>(k) - 1] = 1;
    }
  }

  // The aiming traces ignore clear apertures: an intermediate guess may pass outside a rim that the converged
  // ray clears (Zemax's ray aiming does the same); the caller's trace of the aimed ray clips.
  TracerOptions unclipped;
  unclipped.clip_apertures = false;
  unclipped.image_distance_mm = 0.0;
  Prescription to_stop_lens = lens;
  to_stop_lens.surfaces.resize(static_cast<std::size_t>(stop));
  to_stop_lens.surfaces.back().thickness_mm = 0.0;
  to_stop_lens.image_at_paraxial_focus = false;
  to_stop = std::make_shared<const SequentialTracer>(to_stop_lens, unclipped);
  if (stop > 1) {
    Prescription before = lens;
    before.surfaces.resize(stop_index);
    before.image_at_paraxial_focus = false;
    // Without the stop an aperture that floats by it would not validate; the backward traces need no aperture.
    before.aperture =
        ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 2.0 * std::max({ep_radius, stop_radius, 1.0})};
    before_stop = std::make_shared<const SequentialTracer>(before, unclipped);
  }

  // Paraxial map to the stop: refraction n' u' = n u - y (n' - n) c, transfer y += t u' (conventions.h).
  const double wavelength = paraxial.wavelength_nm();
  auto to_stop_paraxial = [&](double u, double y) {
    double n = tracer.index_after(0, wavelength);
    for (int k = 1; k < stop; ++k) {
      const Surface& s = lens.surfaces[static_cast<std::size_t>(k) - 1];
      const double n_after = tracer.index_after(k, wavelength);
      u = (n * u - y * (n_after - n) * s.paraxial_curvature_per_mm()) / n_after;
      y += s.thickness_mm * u;
      n = n_after;
    }
    return Eigen::Vector2d(u, y);
  };
  const Eigen::Vector2d from_slope = to_stop_paraxial(1.0, 0.0);
  const Eigen::Vector2d from_height = to_stop_paraxial(0.0, 1.0);
  m11 = from_slope.x();
  m21 = from_slope.y();
  m12 = from_height.x();
  m22 = from_height.y();

  // Real chief rays from the stop centre, traced backward at increasing stop-space angles, until the trace
  // dies, the ray no longer leaves toward the object, or its field angle stops growing (a fold: beyond it the
  // stop centre is out of reach, see docs/trace.md).
  if (stop > 1) {
    std::vector<SurfaceHit> path;
    double sign = 0.0;
    for (double angle_deg = 0.0; angle_deg <= kChiefTableMaxDeg; angle_deg += kChiefTableStepDeg) {
      const double alpha = rad_from_deg(angle_deg);
      Ray ray;
      ray.position_mm = Eigen::Vector3d(0.0, 0.0, stop_vertex_z_mm);
      ray.direction = Eigen::Vector3d(0.0, -std::sin(alpha), -std::cos(alpha));
      ray.wavelength_nm = wavelength;
      const TraceResult r = before_stop->trace_backward(ray, &path);
      const Eigen::Vector3d* start = refracts[stop_index] ? &ray.position_mm : nullptr;
      int folded_at = 0;
      if (!r.ok() || !runs_forward(path, refracts, folded_at, start, start ? &ray.direction : nullptr)) break;
      const Eigen::Vector3d f = -r.ray.direction;
      if (!(f.z() > 0.0)) break;
      const double angle = std::atan2(f.y(), f.z());
      if (chief.size() == 1) sign = angle > 0.0 ? 1.0 : (angle < 0.0 ? -1.0 : 0.0);
      if (chief.size() >= 1 && (sign == 0.0 || sign * angle <= sign * chief_angle_rad.back())) break;
      chief.push_back({std::tan(alpha), r.ray.position_mm.y(), r.ray.position_mm.z(), f.y(), f.z()});
      chief_angle_rad.push_back(angle);
    }
  }
}

// The stop-space tangent (signed along the field's azimuth) of the table's chief ray whose `reach` (field
// angle or object-plane height, one value per table entry, 0 at the first) equals `wanted` >= 0: the first
// crossing along the monotone part of the table, or its end when `wanted` lies beyond it.
double RayAimer::StopSolver::signed_chief_tangent(const std::vector<double>& reach, double wanted) const {
  if (reach.size() < 2 || reach[1] == 0.0) return std::nan("");
  const double sign = reach[1] > 0.0 ? 1.0 : -1.0;
  for (std::size_t i = 1; i < reach.size(); ++i) {
    const double here = sign * reach[i];
    const double before = sign * reach[i - 1];
    if (here <= before) return sign * chief[i - 1].tangent;  // the end of the monotone part
    if (here >= wanted) {
      const double s = (wanted - before) / (here - before);
      return sign * (chief[i - 1].tangent + s * (chief[i].tangent - chief[i - 1].tangent));
    }
  }
  return sign * chief.back().tangent;
}

RayAimer::StopSolver::Target RayAimer::StopSolver::target(const Beam& beam, const Eigen::Vector2d& stop_xy) const {
  Target t;
  t.beam = beam;
  t.stop_xy = stop_xy;
  double sag_mm = 0.0;
  t.valid = surface_sag(stop_surface, stop_xy.norm(), sag_mm);
  t.stop_point_mm = Eigen::Vector3d(stop_xy.x(), stop_xy.y(), stop_vertex_z_mm + sag_mm);
  if (beam.parallel) {
    t.nominal = beam.direction;
  } else {
    const Eigen::Vector3d to_pupil = Eigen::Vector3d(0.0, 0.0, geometry.z_ep_mm) - beam.origin;
    t.nominal = to_pupil.norm() > 0.0 ? to_pupil.normalized() : Eigen::Vector3d::UnitZ();
  }
  perpendicular_basis(t.nominal, t.u1, t.u2);
  return t;
}

// Start of the backward solve: the real chief ray of the field from the table (where the table reaches), plus
// the paraxial change of stop-space slope for the offset of the stop point.
Eigen::Vector2d RayAimer::StopSolver::guess(const Target& t) const {
  Eigen::Vector2d chief_v(0.0, 0.0);
  double per_stop_offset = 0.0;  // paraxial d(stop slope) / d(stop height) at a fixed field
  if (t.beam.parallel) {
    const Eigen::Vector3d& d = t.beam.direction;
    const Eigen::Vector2d transverse(d.x(), d.y());
    const double rho = transverse.norm();
    per_stop_offset = m12 / m22;
    if (rho > 0.0) {
      const double tangent = signed_chief_tangent(chief_angle_rad, std::atan2(rho, d.z()));
      // Paraxial chief ray: y_stop = 0 gives y1 = -m21 u0 / m22 and a stop slope (m11 - m12 m21 / m22) u0.
      chief_v = std::isfinite(tangent) ? Eigen::Vector2d(tangent * transverse / rho)
                                       : Eigen::Vector2d((m11 - m12 * m21 / m22) * transverse / d.z());
    }
  } else {
    const Eigen::Vector3d& o = t.beam.origin;
    const Eigen::Vector2d height(o.x(), o.y());
    const double rho = height.norm();
    const double z_o = o.z();
    per_stop_offset = (m11 - m12 * z_o) / (m21 - m22 * z_o);
    if (rho > 0.0) {
      std::vector<double> reach(chief.size());
      for (std::size_t i = 0; i < chief.size(); ++i) {
        reach[i] = chief[i].y1_mm + (z_o - chief[i].z1_mm) * chief[i].fy / chief[i].fz;
      }
      const double tangent = signed_chief_tangent(reach, rho);
      // Paraxial chief ray from height h at z_o: u0 = -m22 h / (m21 - m22 z_o), y1 = h - z_o u0.
      const double u0 = -m22 / (m21 - m22 * z_o);
      chief_v = std::isfinite(tangent) ? Eigen::Vector2d(tangent * height / rho)
                                       : Eigen::Vector2d((m11 * u0 + m12 * (1.0 - z_o * u0)) * height);
    }
  }
  const Eigen::Vector2d v = chief_v + per_stop_offset * t.stop_xy;
  return v.allFinite() ? v : Eigen::Vector2d(0.0, 0.0);
}

RayAimer::StopSolver::Backward RayAimer::StopSolver::backward(const Target& t, const Eigen::Vector2d& v,
                                                             Work& work) const {
  Backward out;
  const Eigen::Vector3d arriving = Eigen::Vector3d(v.x(), v.y(), 1.0).normalized();
  Eigen::Vector3d f = arriving;
  out.on_first = t.stop_point_mm;
  if (before_stop) {
    Ray ray;
    ray.position_mm = t.stop_point_mm;
    ray.direction = -arriving;
    ray.wavelength_nm = work.wavelength_nm;
    const TraceResult r = before_stop->trace_backward(ray, &work.path);
    if (!r.ok()) {
      out.status = r.status;
      out.surface = r.surface;
      return out;
    }
    const bool from_stop = refracts[static_cast<std::size_t>(stop) - 1];
    if (!runs_forward(work.path, refracts, out.surface, from_stop ? &ray.position_mm : nullptr, &ray.direction)) {
      out.status = RayStatus::Missed;
      return out;
    }
    out.on_first = r.ray.position_mm;
    f = -r.ray.direction;
  }
  Eigen::Vector3d g = t.beam.direction;
  if (!t.beam.parallel) {
    const Eigen::Vector3d from_object = out.on_first - t.beam.origin;
    if (!(from_object.norm() > 0.0)) {
      out.status = RayStatus::InvalidInput;
      return out;
    }
    g = from_object.normalized();
  }
  const Eigen::Vector3d difference = f - g;
  out.residual = Eigen::Vector2d(difference.dot(t.u1), difference.dot(t.u2));
  // f - g perpendicular to `nominal` with both along it means f = g (the other root is g's mirror image).
  out.right_way = f.dot(t.nominal) > 0.0 && g.dot(t.nominal) > 0.0;
  if (!out.residual.allFinite()) out.status = RayStatus::NotConverged;
  return out;
}

// Damped Newton (RootSolver2d: forward differences, a trust region, Armijo backtracking) on the
// backward residual from v (updated in place to the best point found), at most max_iterations steps
// and no more than the ray has left.
RayAimer::StopSolver::Outcome RayAimer::StopSolver::newton(const Target& t, Eigen::Vector2d& v, Backward& at_v,
                                                          double tolerance, int max_iterations, Work& work) const {
  RootSolver2dOptions o;
  o.tolerance = tolerance;
  o.max_iterations = std::max(0, std::min(max_iterations, work.iterations_left));
  o.difference_step = kTangentStep;
  o.max_step = kMaxTangentStep;
  o.armijo = kArmijo;
  o.max_halvings = kMaxStepHalvings;
  Backward last;
  auto residual = [&](const Vector2& x, Vector2& r, Matrix2*) {
    last = backward(t, Eigen::Vector2d(x[0], x[1]), work);
    if (!last.alive()) return false;
    r = {last.residual.x(), last.residual.y()};
    return true;
  };
  Vector2 x{v.x(), v.y()};
  const RootSolver2dSummary summary = RootSolver2d(o).solve(residual, x, nullptr, [&] { at_v = last; });
  v = Eigen::Vector2d(x[0], x[1]);
  work.iterations_left -= summary.iterations;
  switch (summary.status) {
    case RootSolver2dStatus::Converged: return at_v.right_way ? Outcome::Converged : Outcome::Stalled;
    case RootSolver2dStatus::FailedAtStart: at_v = last; return Outcome::Died;
    case RootSolver2dStatus::OutOfIterations: return Outcome::OutOfIterations;
    default: return Outcome::Stalled;  // a dead neighbour on both sides, a singular Jacobian, no decrease
  }
}

// Continuation: from the solution v of target_at(0) to that of target_at(1), in adaptive steps with a secant
// predictor; intermediate steps are solved loosely, the last one to kBackwardTolerance_rad.
template <typename TargetAt>
bool RayAimer::StopSolver::follow(TargetAt target_at, Eigen::Vector2d& v, Backward& at_v, Work& work) const {
  double reached = 0.0;
  double previous_reached = 0.0;
  Eigen::Vector2d previous_v = v;
  bool have_previous = false;
  double increment = kFirstContinuationStep;
  while (reached < 1.0) {
    const double next = std::min(1.0, reached + increment);
    Eigen::Vector2d trial = v;
    if (have_previous) trial += (next - reached) / (reached - previous_reached) * (v - previous_v);
    Backward at_trial;
    const bool last = next == 1.0;
    const Outcome outcome = newton(target_at(next), trial, at_trial,
                                   last ? kBackwardTolerance_rad : kTrackingTolerance_rad, kCorrectorIterations, work);
    const bool usable = outcome == Outcome::Converged ||
                        (last && outcome == Outcome::Stalled && at_trial.alive() && at_trial.right_way &&
                         at_trial.residual.norm() <= kBackwardUsable_rad);
    if (usable) {
      previous_v = v;
      previous_reached = reached;
      have_previous = true;
      v = trial;
      at_v = at_trial;
      reached = next;
      increment = std::min(2.0 * increment, kMaxContinuationStep);
    } else {
      increment *= 0.5;
      if (increment < kMinContinuationStep || work.iterations_left <= 0) return false;
    }
  }
  return true;
}

// The forward ray from the backward solution, polished by Newton on its miss at the stop. Unknowns: for a
// parallel beam the ray's offset in its start wavefront, for an object point the direction's components
// perpendicular to `nominal`. True when the forward trace reaches the stop point within tolerance_mm along a
// path that runs forward through every surface.
bool RayAimer::StopSolver::polish(const Target& t, const Backward& solved, Ray& ray, Work& work) const {
  const Eigen::Vector3d ep_centre(0.0, 0.0, geometry.z_ep_mm);
  const Eigen::Vector3d wavefront_centre =
      t.beam.parallel ? Eigen::Vector3d(ep_centre - t.beam.wavefront_distance_mm * t.beam.direction) : ep_centre;
  auto make = [&](const Eigen::Vector2d& w) {
    Ray r;
    r.wavelength_nm = work.wavelength_nm;
    if (t.beam.parallel) {
      r.position_mm = wavefront_centre + w.x() * t.u1 + w.y() * t.u2;
      r.direction = t.beam.direction;
    } else {
      r.position_mm = t.beam.origin;
      r.direction = (t.nominal + w.x() * t.u1 + w.y() * t.u2).normalized();
    }
    return r;
  };
  const std::size_t stop_index = static_cast<std::size_t>(stop) - 1;
  auto miss = [&](const Eigen::Vector2d& w, Eigen::Vector2d& residual) {
    const Ray r = make(w);
    to_stop->trace_forward(r, &work.path);
    if (work.path.size() <= stop_index) return false;
    int behind = 0;
    if (!runs_forward(work.path, refracts, behind)) return false;
    residual = Eigen::Vector2d(work.path[stop_index].point_mm.x(), work.path[stop_index].point_mm.y()) - t.stop_xy;
    return residual.allFinite();
  };

  Eigen::Vector2d w;
  double step = kJacobianRelativeStep * std::max(ep_radius_mm, stop_radius_mm);
  if (t.beam.parallel) {
    const Eigen::Vector3d offset = solved.on_first - wavefront_centre;
    w = Eigen::Vector2d(offset.dot(t.u1), offset.dot(t.u2));
  } else {
    const Eigen::Vector3d g = (solved.on_first - t.beam.origin).normalized();
    w = Eigen::Vector2d(g.dot(t.u1), g.dot(t.u2)) / g.dot(t.nominal);
    step /= std::max((ep_centre - t.beam.origin).norm(), std::max(ep_radius_mm, stop_radius_mm));
  }
  // Newton (RootSolver2d) on the miss, differences of `step`, halving until the miss falls.
  if (!(std::isfinite(step) && step > 0.0)) return false;  // a pupil of no size
  RootSolver2dOptions o;
  o.tolerance = options.tolerance_mm;
  o.max_iterations = std::max(0, work.iterations_left);
  o.difference_step = step;
  o.max_halvings = kMaxStepHalvings;
  auto residual = [&](const Vector2& x, Vector2& r, Matrix2*) {
    Eigen::Vector2d e;
    if (!miss(Eigen::Vector2d(x[0], x[1]), e)) return false;
    r = {e.x(), e.y()};
    return true;
  };
  Vector2 x{w.x(), w.y()};
  const RootSolver2dSummary summary = RootSolver2d(o).solve(residual, x);
  work.iterations_left -= summary.iterations;
  if (!summary.converged()) return false;
  w = Eigen::Vector2d(x[0], x[1]);
  ray = make(w);
  return true;
}

AimedRay RayAimer::StopSolver::aim(const FieldPoint& field, const Eigen::Vector2d& stop_xy,
                                   double wavelength_nm) const {
  AimedRay out;
  Work work;
  work.wavelength_nm = wavelength_nm;
  work.path.reserve(static_cast<std::size_t>(stop));
  work.iterations_left = options.max_iterations;
  const Target wanted = target(beam_of(field, 1.0, geometry), stop_xy);
  if (!wanted.valid) {
    out.status = RayStatus::Missed;  // the point is not on the stop surface (beyond its sag's domain)
    out.surface = stop;
    return out;
  }
  auto usable = [](Outcome outcome, const Backward& b) {
    return outcome == Outcome::Converged ||
           (outcome == Outcome::Stalled && b.alive() && b.right_way && b.residual.norm() <= kBackwardUsable_rad);
  };
  auto accept = [&](const Backward& solved) {
    if (!polish(wanted, solved, out.ray, work)) return false;
    out.status = RayStatus::Ok;
    out.surface = 0;
    return true;
  };

  // 1. Directly from the table's chief ray and the paraxial pupil offset.
  Eigen::Vector2d v = guess(wanted);
  Backward solved;
  const Outcome direct = newton(wanted, v, solved, kBackwardTolerance_rad, kCorrectorIterations, work);
  if (usable(direct, solved) && accept(solved)) return out;
  // If nothing works, the caller hears how the direct attempt failed: the status of its dying trace, or
  // NotConverged at the stop (also whenever the iteration budget ran out).
  auto failure = [&]() {
    const bool died = direct == Outcome::Died && work.iterations_left > 0;
    out.status = died ? solved.status : RayStatus::NotConverged;
    out.surface = died ? solved.surface : stop;
    return out;
  };

  // 2. Pupil continuation: from this field's chief ray (through the stop centre) out to the stop point.
  if (stop_xy.x() != 0.0 || stop_xy.y() != 0.0) {
    const Target centre = target(wanted.beam, Eigen::Vector2d(0.0, 0.0));
    Eigen::Vector2d chief_v = guess(centre);
    Backward at_chief;
    if (usable(newton(centre, chief_v, at_chief, kTrackingTolerance_rad, kCorrectorIterations, work), at_chief) &&
        follow([&](double s) { return target(wanted.beam, s * stop_xy); }, chief_v, at_chief, work) &&
        accept(at_chief)) {
      return out;
    }
  }

  // 3. Field continuation: from the axis (where the paraxial start is good) out to the field, at this stop point.
  const Target on_axis = target(beam_of(field, 0.0, geometry), stop_xy);
  Eigen::Vector2d axis_v = guess(on_axis);
  Backward at_axis;
  if (usable(newton(on_axis, axis_v, at_axis, kTrackingTolerance_rad, kCorrectorIterations, work), at_axis) &&
      follow([&](double s) { return target(beam_of(field, s, geometry), stop_xy); }, axis_v, at_axis, work) &&
      accept(at_axis)) {
    return out;
  }
  return failure();
}

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
  if (options_.aiming == RayAiming::RealStop) {
    if (const auto why = lens.why_no_real_ray_aiming()) {
      throw OptionsError("real ray aiming is implemented for rotationally symmetric refracting lenses, not for this one (" +
                         *why + "): aim at the paraxial entrance pupil (--aim paraxial)");
    }
  }
  const int stop = paraxial_.stop_surface();
  // Pupil coordinate 1 is the edge of the beam the aperture specification defines (as in Zemax): the
  // paraxial marginal height at the stop, which is the stop's semi-diameter when the aperture floats by
  // it; under RealStop aiming with an EPD, F/# or NA, the real axial ray's height (below).
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

  if (options_.aiming == RayAiming::RealStop) {
    const BeamGeometry geometry{paraxial_.entrance_pupil().z_mm, paraxial_.object_distance_mm(), front_z_mm_,
                                beam_radius_mm_};
    if (lens.aperture.kind != ApertureSpec::Kind::FloatByStop) {
      // An EPD, F/# or NA sets the beam in object space, and OpticStudio's real ray aiming fills the stop to
      // where the real axial ray through the edge of the paraxial entrance pupil crosses it (its automatic
      // stop semi-diameter is that height: 4.215000 mm against the paraxial 4.250827 in the US 583,336
      // double Gauss of tests/data/zemax/real). The paraxial height stays where no such ray gets there.
      const bool at_infinity = std::isinf(paraxial_.object_distance_mm());
      const Beam beam = beam_of(at_infinity ? FieldPoint::angle_deg(0.0) : FieldPoint::object_height_mm(0.0), 1.0, geometry);
      Ray axial;
      std::vector<SurfaceHit> path;
      if (ray_through(beam, 0.0, ep_radius_mm, geometry.z_ep_mm, lens.primary_wavelength_nm(), axial)) {
        tracer_.trace_forward(axial, &path);
        for (const SurfaceHit& hit : path) {
          if (hit.surface == stop && std::isfinite(hit.point_mm.y())) stop_radius_mm_ = std::hypot(hit.point_mm.x(), hit.point_mm.y());
        }
      }
    }
    stop_solver_ =
        std::make_shared<const StopSolver>(tracer_, paraxial_, stop_radius_mm_, ep_radius_mm, geometry, options_);
  }
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
      // The object point on the chief ray of this slope: below the axis for a rising chief ray.
      return FieldPoint::object_height_mm(-slope * (paraxial_.object_distance_mm() + paraxial_.entrance_pupil().z_mm));
    }
    case FieldSpec::Kind::RealImageHeightMm: break;  // ParaxialSystem refused it: resolve_real_image_height_field first
  }
  return FieldPoint::angle_deg(0.0);
}

PupilCoordinate RayAimer::vignetted_pupil(const FieldPoint& field, const PupilCoordinate& pupil) const {
  const std::optional<FieldSpec>& spec = tracer_.lens().field;
  if (!options_.use_vignetting_factors || !spec || spec->vignetting.empty()) return pupil;
  // The field point's value in the units of the lens's field, to interpolate its factors.
  double value = std::numeric_limits<double>::quiet_NaN();
  const double radial_angle_deg = radial_field_value(FieldSpec::Kind::AngleDeg, field.x, field.y);
  // The field's azimuth (from +y toward +x) in the frame the file's factors hold in: that of the
  // object point or angle, except for image-height fields, whose points field_at() puts at the object
  // point below the axis that images above it.
  double phi = (field.x == 0.0 && field.y >= 0.0) ? 0.0 : std::atan2(field.x, field.y);
  switch (spec->kind) {
    case FieldSpec::Kind::AngleDeg:
      if (field.kind == FieldPoint::Kind::AngleDeg) value = radial_angle_deg;
      break;
    case FieldSpec::Kind::ObjectHeightMm:
      if (field.kind == FieldPoint::Kind::ObjectHeightMm) value = std::hypot(field.x, field.y);
      break;
    case FieldSpec::Kind::ImageHeightMm: {
      // Paraxial image heights are linear in the chief ray's object-space slope.
      const double max_slope = paraxial_.chief_ray() ? std::abs(paraxial_.chief_ray()->object_slope) : 0.0;
      double slope = std::numeric_limits<double>::quiet_NaN();
      if (field.kind == FieldPoint::Kind::AngleDeg) slope = std::tan(rad_from_deg(radial_angle_deg));
      if (field.kind == FieldPoint::Kind::ObjectHeightMm) {
        slope = std::hypot(field.x, field.y) / std::abs(paraxial_.object_distance_mm() + paraxial_.entrance_pupil().z_mm);
        phi = (field.x == 0.0 && field.y <= 0.0) ? 0.0 : std::atan2(-field.x, -field.y);
      }
      if (max_slope > 0.0) value = slope / max_slope * spec->max_value();
      break;
    }
    case FieldSpec::Kind::RealImageHeightMm: break;  // resolved into angles or heights before any aiming
  }
  if (!std::isfinite(value)) return pupil;
  const VignettingFactors v = spec->vignetting_at(value);
  if (v.is_none()) return pupil;
  // The factors hold for a field along +y; a field at azimuth phi turns them with it.
  const double c = std::cos(phi), s = std::sin(phi);
  // Into the field's frame, scale and shift there, turn by VAN about the vignetted centre, and back.
  const double u = c * pupil.px - s * pupil.py, w = s * pupil.px + c * pupil.py;
  const double a = rad_from_deg(v.van_deg);
  const double du = u * (1.0 - v.vcx), dw = w * (1.0 - v.vcy);
  const double fu = v.vdx + std::cos(a) * du - std::sin(a) * dw;
  const double fw = v.vdy + std::sin(a) * du + std::cos(a) * dw;
  return {c * fu + s * fw, -s * fu + c * fw};
}

AimedRay RayAimer::make_ray(const FieldPoint& field, const PupilCoordinate& requested, double wavelength_nm) const {
  const PupilCoordinate pupil = vignetted_pupil(field, requested);
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

  if (field.kind == FieldPoint::Kind::AngleDeg && !(std::abs(field.x) < 90.0 && std::abs(field.y) < 90.0)) {
    out.status = RayStatus::InvalidInput;
    return out;
  }
  if (field.kind == FieldPoint::Kind::ObjectHeightMm && std::isinf(object_distance)) {
    throw OptionsError("FieldPoint " + field.to_string() +
                       ": an object-height field needs a finite object distance (the object is at infinity)");
  }
  const BeamGeometry geometry{z_ep, object_distance, front_z_mm_, beam_radius_mm_};
  const Beam beam = beam_of(field, 1.0, geometry);
  // The paraxial-pupil ray: the answer of ParaxialEntrancePupil aiming, and the reference ray of a failed real aim.
  const bool through_pupil =
      ray_through(beam, pupil.px * ep_radius, pupil.py * ep_radius, z_ep, wavelength_nm, out.ray);
  if (options_.aiming == RayAiming::ParaxialEntrancePupil) {
    if (!through_pupil) out.status = RayStatus::InvalidInput;
    return out;
  }

  const AimedRay aimed =
      stop_solver_->aim(field, Eigen::Vector2d(pupil.px * stop_radius_mm_, pupil.py * stop_radius_mm_), wavelength_nm);
  if (!aimed.ok()) {
    out.status = aimed.status;
    out.surface = aimed.surface;
    return out;
  }
  return aimed;
}

namespace {

// How closely a resolved field point's real chief ray must land on its image height: 1e-9 mm, relative
// above 1 mm, far below the 1e-6 digits OpticStudio prints and far above the rounding of a trace.
constexpr double kRealImageHeightTolerance = 1e-9;
constexpr int kMaxRealImageHeightIterations = 60;

}  // namespace

Prescription resolve_real_image_height_field(const Prescription& lens) {
  if (!lens.field || lens.field->kind != FieldSpec::Kind::RealImageHeightMm) return lens;
  Prescription probe = lens;
  probe.field->kind = FieldSpec::Kind::ImageHeightMm;  // the paraxial estimate starts each solve
  for (double& v : probe.field->values) v = std::abs(v);
  TracerOptions free;
  free.clip_apertures = false;
  const SequentialTracer tracer(probe, free);
  AimOptions aim;
  aim.aiming = lens.ray_aiming;
  const RayAimer aimer(tracer, aim);
  const bool at_infinity = std::isinf(lens.object_distance_mm);
  const double wavelength_nm = lens.primary_wavelength_nm();
  const double max_height = probe.field->max_value();

  auto field_point = [&](double t) { return at_infinity ? FieldPoint::angle_deg(t) : FieldPoint::object_height_mm(t); };
  // The real chief ray's image height for the field parameter t (deg or mm); NaN when it cannot be traced.
  auto landing = [&](double t) {
    if (at_infinity && !(std::abs(t) < 90.0)) return std::numeric_limits<double>::quiet_NaN();
    const AimedRay aimed = aimer.make_ray(field_point(t), {0.0, 0.0}, wavelength_nm);
    if (!aimed.ok()) return std::numeric_limits<double>::quiet_NaN();
    const TraceResult r = tracer.trace_forward(aimed.ray);
    return r.ok() ? r.ray.position_mm.y() : std::numeric_limits<double>::quiet_NaN();
  };

  Prescription out = lens;
  out.field->kind = at_infinity ? FieldSpec::Kind::AngleDeg : FieldSpec::Kind::ObjectHeightMm;
  for (std::size_t i = 0; i < probe.field->values.size(); ++i) {
    const double height = probe.field->values[i];
    if (height == 0.0) {
      out.field->values[i] = 0.0;
      continue;
    }
    const FieldPoint guess = aimer.field_at(height / max_height);
    double t0 = guess.y;
    double y0 = landing(t0);
    auto unreachable = [&](const std::string& why) {
      return ComputationError("field: real image height " + std::to_string(height) + " mm: " + why +
                              " (beyond the image circle of the lens?)");
    };
    if (!std::isfinite(y0)) throw unreachable("the chief ray of its paraxial estimate cannot be traced");
    const double target = std::copysign(height, y0);
    const double tolerance = kRealImageHeightTolerance * std::max(1.0, height);
    double t1 = t0 * (1.0 + 1e-4);
    double y1 = landing(t1);
    bool done = std::abs(y0 - target) <= tolerance;
    double best = t0;
    for (int k = 0; !done && k < kMaxRealImageHeightIterations; ++k) {
      if (!std::isfinite(y1) || y1 == y0) {
        t1 = 0.5 * (t0 + t1);  // back off towards the last good point
        y1 = landing(t1);
        continue;
      }
      const double t2 = t1 - (y1 - target) * (t1 - t0) / (y1 - y0);
      t0 = t1;
      y0 = y1;
      t1 = t2;
      y1 = landing(t1);
      if (std::isfinite(y1) && std::abs(y1 - target) <= tolerance) {
        best = t1;
        done = true;
      }
    }
    if (!done) throw unreachable("no chief ray lands there");
    out.field->values[i] = std::abs(best);
  }
  return out;
}

}  // namespace lensmith

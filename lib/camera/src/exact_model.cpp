// The exact model: for each scene point, a ray to every requested point of the aperture stop,
// traced through the prescription onto the sensor. Aiming: three unclipped traces from the scene
// point give the affine map from entrance-pupil-plane targets to stop points; each pupil point's
// target is its inverse image, refined by Newton steps with that Jacobian until the ray crosses the
// stop within 1e-4 of its radius; the final trace records how far inside every clear aperture the
// ray passes (vignetting, and where the edge of a clipped beam lies between rays). Each ray's
// radiometric weight is the solid angle of its entrance-pupil-plane element seen from the point,
// the element's area per unit stop area taken from the aiming's Jacobian (SensorHit).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "lensmith/core/errors.h"
#include "lensmith/core/root_solver_2d.h"
#include "lensmith/core/units.h"
#include "model_implementations.h"

namespace lensmith::camera_detail {

namespace {

// Builds the ray from the scene point towards a target on the entrance-pupil plane.
Ray ray_towards(const ScenePoint& p, double z_perspective_mm, double target_x, double target_y, double target_z,
                double wavelength_nm, double start_z_mm) {
  Ray r;
  r.wavelength_nm = wavelength_nm;
  if (p.inverse_depth_per_mm > 0.0) {
    const double depth = distance_mm_from_inverse(p.inverse_depth_per_mm);
    r.position_mm = Eigen::Vector3d(p.tan_x * depth, p.tan_y * depth, z_perspective_mm - depth);
    const Eigen::Vector3d target(target_x, target_y, target_z);
    r.direction = (target - r.position_mm).normalized();
    // A far point starts its ray near the lens, on the same line: traced from 1e10 mm away (a renderer's
    // sky depth: Cycles writes 1e10 m) the intersections lost their precision, and beyond 1e8 m the rays
    // missed (a sky that vanished under --model exact).
    if (r.position_mm.z() < start_z_mm) r.position_mm = target + r.direction * ((start_z_mm - target_z) / r.direction.z());
  } else {
    // Light from a point infinitely far along +tangents travels along -tangents.
    r.direction = Eigen::Vector3d(-p.tan_x, -p.tan_y, 1.0).normalized();
    const Eigen::Vector3d target(target_x, target_y, target_z);
    r.position_mm = target + r.direction * ((start_z_mm - target_z) / r.direction.z());
  }
  return r;
}

// Pupil points within this radius (1: the stop's rim, with its edge tolerance) get RayAimer's
// fallback aim.
constexpr double kOnStop = 1.0 + kStopEdgeTolerance;

}  // namespace

ExactModel::ExactModel(const Camera& camera) : RayModel(camera) {
  const Prescription& lens = *camera.lens();
  TracerOptions free;
  free.image_distance_mm = camera.z_sensor_mm() - lens.last_vertex_z_mm();
  // The stop Camera::from_lens sized to the f-number: the one ParaxialSystem finds.
  const ParaxialSystem p(lens);
  stop_surface_ = p.stop_surface();
  stop_radius_mm_ = lens.surfaces[static_cast<std::size_t>(stop_surface_ - 1)].semi_diameter_mm.value_or(0.0);
  free.clip_apertures = false;
  free_ = std::make_shared<SequentialTracer>(lens, free);
  // The clear apertures that clip, as (0-based surface index, semi-diameter); the stop with the
  // margin of kStopEdgeTolerance.
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    const Surface& s = lens.surfaces[k];
    if (s.aperture && static_cast<int>(k) + 1 != stop_surface_) {
      apertures_.push_back({static_cast<int>(k) + 1, 0.0, *s.aperture});  // as the tracer clips: the explicit aperture instead of the circle
      continue;
    }
    const std::optional<double>& r = s.semi_diameter_mm;
    if (!r || !(*r > 0.0)) continue;
    apertures_.push_back({static_cast<int>(k) + 1, static_cast<int>(k) + 1 == stop_surface_ ? *r * (1.0 + kStopEdgeTolerance) : *r, std::nullopt});
  }
  z_stop_mm_ = free_->vertex_z_mm(stop_surface_);
  for (int k = 1; k <= static_cast<int>(lens.surfaces.size()); ++k) frames_.push_back(free_->surface_frame(k));
  stop_frame_ = frames_[static_cast<std::size_t>(stop_surface_ - 1)];
  AimOptions aim;
  aim.aiming = RayAiming::RealStop;
  aim.tolerance_mm = kAimTolerance * stop_radius_mm_;
  aim.use_vignetting_factors = false;  // the camera's rays fill the stop; vignetting is traced
  // RayAimer aims through rotationally symmetric refracting lenses only; the others (tilts,
  // mirrors) have the beam's own aim alone.
  if (aim.tolerance_mm > 0.0) {
    try {
      aimer_ = std::make_shared<RayAimer>(*free_, aim);
    } catch (const OptionsError&) {
      aimer_ = nullptr;
    }
  }
  normalisation_ = weight_normalisation_for(camera, [this](auto&&... a) { map_raw(a...); });
  unaimed_ = 0;  // the count is of the caller's rays
}

bool ExactModel::aim_by_ray_aimer(const ScenePoint& point, double wavelength_nm, double want_x_mm, double want_y_mm,
                                  double z_target_mm, double& target_x_mm, double& target_y_mm) const {
  if (!aimer_ || !(aimer_->stop_radius_mm() > 0.0)) return false;
  const double z_persp = camera_.z_perspective_mm();
  FieldPoint field;
  if (point.inverse_depth_per_mm > 0.0) {
    const double depth = distance_mm_from_inverse(point.inverse_depth_per_mm);
    field = FieldPoint::object_point_mm(Eigen::Vector3d(point.tan_x * depth, point.tan_y * depth, z_persp - depth));
  } else {
    // Light from infinitely far along +tangents travels along -tangents.
    field = FieldPoint::angle_deg(deg_from_rad(std::atan(-point.tan_y)), deg_from_rad(std::atan(-point.tan_x)));
  }
  const double r = aimer_->stop_radius_mm();
  const AimedRay aimed = aimer_->make_ray(field, PupilCoordinate{want_x_mm / r, want_y_mm / r}, wavelength_nm);
  if (!aimed.ok() || !(std::abs(aimed.ray.direction.z()) > 0.0)) return false;
  const double t = (z_target_mm - aimed.ray.position_mm.z()) / aimed.ray.direction.z();
  target_x_mm = aimed.ray.position_mm.x() + t * aimed.ray.direction.x();
  target_y_mm = aimed.ray.position_mm.y() + t * aimed.ray.direction.y();
  return std::isfinite(target_x_mm) && std::isfinite(target_y_mm);
}

void ExactModel::map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                     std::span<SensorHit> hits) const {
  map_raw(point, wavelength_nm, pupil, hits);
  normalisation_.apply(wavelength_nm, hits);
}

void ExactModel::map_raw(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                         std::span<SensorHit> hits) const {
  // The hits of the last trace up to the stop, and of the rest of the lens (the final ray's).
  thread_local std::vector<SurfaceHit> path, rear;
  const FirstOrderSample fo = camera_.first_order(wavelength_nm);
  const double z_target = fo.z_entrance_pupil_mm;
  const double r_target = fo.entrance_pupil_radius_mm;
  const double start_z = std::min(0.0, z_target) - 10.0 - r_target;
  const double z_persp = camera_.z_perspective_mm();
  const std::size_t stop_index = static_cast<std::size_t>(stop_surface_ - 1);

  const int last_surface = static_cast<int>(frames_.size());
  // Stop point of the unclipped ray towards an entrance-pupil-plane target; false if it fails. Traced
  // only up to the stop (the surfaces behind it cannot move where it crosses the stop): aiming is
  // most of the model's traces, and the aimed ray goes on from the stop once (below). `path` keeps
  // the hits and `traced` the target, so that the aimed ray's own last trace is not repeated.
  TraceResult front;
  double traced_x = std::numeric_limits<double>::quiet_NaN(), traced_y = traced_x;
  auto stop_point = [&](double tx, double ty, double& sx, double& sy) {
    const Ray r = ray_towards(point, z_persp, tx, ty, z_target, wavelength_nm, start_z);
    traced_x = tx;
    traced_y = ty;
    front = free_->trace_forward_through(r, 1, stop_surface_, &path);
    if (!front.ok() || path.size() <= stop_index) {
      traced_x = std::numeric_limits<double>::quiet_NaN();
      return false;
    }
    // In the stop's own frame (a tilted or shifted lens's stop turns and moves with it).
    const Eigen::Vector3d on_stop = stop_frame_.to_local(path[stop_index].point_mm);
    sx = on_stop.x();
    sy = on_stop.y();
    return true;
  };

  // Affine map target -> stop point from the centre and two offsets at half the pupil radius. The
  // centre: the paraxial chief ray's crossing of the target plane. An anamorphic lens's x section has
  // its own entrance pupil (a front anamorphic group's lies far from the y section's): the chief ray
  // heads for it in x, and a ray towards the y pupil's centre would miss the rear group off axis
  // (lentil's Schneider anamorphic, entry 2004: beyond tan x = 0.2 at 30 m).
  double cx = 0.0, cy = 0.0;
  double hx = 0.5 * r_target;
  if (const std::optional<FirstOrderSample>& xs = camera_.x_section()) {
    const double z_x = xs->z_entrance_pupil_mm;
    if (point.inverse_depth_per_mm > 0.0) {
      const double depth = distance_mm_from_inverse(point.inverse_depth_per_mm);
      const double x0 = point.tan_x * depth, z0 = z_persp - depth;
      if (z_x != z0) cx = x0 * (1.0 - (z_target - z0) / (z_x - z0));
    } else {
      cx = -point.tan_x * (z_target - z_x);
    }
    hx = 0.5 * xs->entrance_pupil_radius_mm;
  }
  const double h = 0.5 * r_target;
  // The affine map target -> stop point about target (ox, oy): the stop point there and the Jacobian
  // from central differences at +-hx and +-h (one-sided where a ray on the minus side fails). Central,
  // because the beam's area ratio below (every ray's radiometric weight) comes from it: one-sided
  // differences over half the pupil tilted it towards their +x, +y side, and through pbrt-dgauss-50mm
  // at f/2 a frame's corners at 45 and 225 deg came out 0.799 and 0.859 of the axis where the lens is
  // round (tests/camera: the weights at every azimuth agree).
  double s0x = 0.0, s0y = 0.0, j11 = 0.0, j21 = 0.0, j12 = 0.0, j22 = 0.0, det = 0.0;
  auto beam_map = [&](double ox, double oy) {
    double ax, ay, bx, by, cx_, cy_, dx, dy, zx, zy;
    if (!stop_point(ox, oy, zx, zy) || !stop_point(ox + hx, oy, ax, ay) || !stop_point(ox, oy + h, bx, by)) return false;
    double k11 = (ax - zx) / hx, k21 = (ay - zy) / hx, k12 = (bx - zx) / h, k22 = (by - zy) / h;
    if (stop_point(ox - hx, oy, cx_, cy_) && stop_point(ox, oy - h, dx, dy)) {
      k11 = (ax - cx_) / (2.0 * hx), k21 = (ay - cy_) / (2.0 * hx), k12 = (bx - dx) / (2.0 * h), k22 = (by - dy) / (2.0 * h);
    }
    const double d = k11 * k22 - k12 * k21;
    if (!(std::abs(d) > 0.0) || !std::isfinite(d)) return false;
    s0x = zx, s0y = zy;
    j11 = k11, j21 = k21, j12 = k12, j22 = k22, det = d;
    return true;
  };
  if (!beam_map(cx, 0.0)) {
    for (auto& hit : hits) hit = {};
    return;
  }
  // Where the beam's centre lies far from the first-order chief ray's (a shifted or tilted lens's
  // entrance pupil moves with its elements: 6 mm of shift put the differences above at the rim of a
  // 9-mm pupil, and the one-sided Jacobian there made the beam's light 5 % brighter on one side of the
  // frame than the other), the map is taken again about the target that one Newton step sends to the
  // stop's centre. Coaxial lenses' chief rays land close enough that nothing changes for them.
  constexpr double kRecentreMiss = 0.05;  // of the stop radius
  if (std::hypot(s0x, s0y) > kRecentreMiss * stop_radius_mm_) {
    const double moved_x = cx - (j22 * s0x - j12 * s0y) / det, moved_y = -(-j21 * s0x + j11 * s0y) / det;
    if (beam_map(moved_x, moved_y)) {  // (which keeps the first map where it fails)
      cx = moved_x;
      cy = moved_y;
    }
  }
  const double i11 = j22 / det, i12 = -j12 / det, i21 = -j21 / det, i22 = j11 / det;
  // Entrance-pupil-plane area per unit stop area, across this beam (the real entrance pupil grows
  // off axis where the stop's image does): with the solid angle of each target seen from the point,
  // the ray's radiometric weight.
  const double target_area = std::abs(i11 * i22 - i12 * i21);
  const Matrix2 beam_jacobian{j11, j12, j21, j22};
  // Each pupil point's aim: at most kAimIterations traces, full steps.
  RootSolver2dOptions aim_options;
  aim_options.jacobian = JacobianSource::Broyden;
  aim_options.line_search = false;
  aim_options.tolerance = kAimTolerance * stop_radius_mm_;
  aim_options.max_iterations = kAimIterations - 1;
  const RootSolver2d aim_solver(aim_options);

  // How far the last aimed ray's target lay from the affine guess. The points of a pupil mesh come
  // ring by ring and sector by sector, and neighbours need nearly the same correction: each starts
  // from its guess moved by its predecessor's.
  double carried_x = 0.0, carried_y = 0.0;
  for (std::size_t i = 0; i < pupil.size(); ++i) {
    const double want_x = pupil[i].x * stop_radius_mm_, want_y = pupil[i].y * stop_radius_mm_;
    const Vector2 guess{cx + i11 * (want_x - s0x) + i12 * (want_y - s0y), cy + i21 * (want_x - s0x) + i22 * (want_y - s0y)};
    Vector2 target{guess[0] + carried_x, guess[1] + carried_y};
    // Quasi-Newton from the beam's Jacobian, updated by Broyden's rank-one rule from each step's
    // change on the stop: at the rim of a strongly aberrated pupil (the Sasian triplet's frame at
    // 1.2 m) the beam's Jacobian alone converges too slowly, and a ray given up there took the
    // light of its mesh triangles with it (a uniform wall rendered up to 20 % dark, in bands).
    auto miss = [&](const Vector2& t, Vector2& r, Matrix2*) {
      double sx, sy;
      if (!stop_point(t[0], t[1], sx, sy)) return false;
      r = {sx - want_x, sy - want_y};
      return true;
    };
    // Where the beam's own aim fails for a point of the stop (a rim ray of a strongly aberrated
    // pupil, a beam the affine start misjudges), RayAimer's continuation; a ray neither can aim is
    // counted as a failure. Points beyond the stop's rim (a square grid's corners, a mask picture's)
    // are not worth RayAimer's 20-120 us refusal: the stop blocks them, and no such ray may exist
    // (validate's PSF grids took 40 % longer with it).
    const bool on_stop = pupil[i].x * pupil[i].x + pupil[i].y * pupil[i].y <= kOnStop * kOnStop;
    // RayAimer's ray is checked the way the beam's own are: traced from this point through its
    // target, in the stop's own frame (which also refuses a ray of another beam, such as a lens
    // file's finite object plane would give for an angle).
    auto aimed_by_ray_aimer = [&]() {
      Vector2 r;
      return on_stop && aim_by_ray_aimer(point, wavelength_nm, want_x, want_y, z_target, target[0], target[1]) &&
             miss(target, r, nullptr) && norm_2d(r) <= aim_options.tolerance;
    };
    if (!aim_solver.solve(miss, target, &beam_jacobian).converged() && !aimed_by_ray_aimer()) {
      hits[i] = {};
      if (on_stop) unaimed_.fetch_add(1, std::memory_order_relaxed);
      carried_x = carried_y = 0.0;
      continue;
    }
    carried_x = target[0] - guess[0];
    carried_y = target[1] - guess[1];
    const double tx = target[0], ty = target[1];
    const double weight = target_area * patch_solid_angle(point, z_persp, tx, ty, z_target);
    // The aimed ray from the stop on, unclipped: where it lands, and how far inside the tightest clear
    // aperture it passes (a stopped ray still lands, for the edge of the beam between rays).
    if (!(traced_x == tx && traced_y == ty)) {
      double sx, sy;
      if (!stop_point(tx, ty, sx, sy)) {
        hits[i] = SensorHit{};
        continue;
      }
    }
    const SurfaceHit& at_stop = path[stop_index];
    const TraceResult f = stop_surface_ < last_surface
                              ? free_->trace_forward_through(Ray{at_stop.point_mm, at_stop.direction_after, wavelength_nm},
                                                             stop_surface_ + 1, last_surface, &rear)
                              : front;
    if (!f.ok()) {
      hits[i] = SensorHit{};
      continue;
    }
    double clearance = 1.0;
    for (const ClipSurface& c : apertures_) {
      const std::size_t k = static_cast<std::size_t>(c.surface - 1);
      const Eigen::Vector3d& on_surface = k <= stop_index ? path[k].point_mm : rear[k - stop_index - 1].point_mm;
      const Eigen::Vector3d p = frames_[k].to_local(on_surface);
      clearance = std::min(clearance, c.clearance(p.x(), p.y()));
    }
    hits[i] = SensorHit{f.ray.position_mm.x(), f.ray.position_mm.y(), clearance >= 0.0, true, weight, clearance};
  }
}

}  // namespace lensmith::camera_detail

// The poly model: the renderer's forward path (from a scene point through a chosen stop point) on a
// polynomial fit of the lens. Hanika & Dachsbacher (2014, sec. 4) solve the same problem by Newton
// iteration on their fitted polynomials; here the unknown is the ray's crossing of the outer plane,
// its direction following from the scene point, and the residual is the fitted stop position.
#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/root_solver_2d.h"
#include "model_implementations.h"

namespace lensmith::camera_detail {

CorePlacement CorePlacement::of(const Camera& camera) {
  const Prescription& lens = *camera.lens();
  const std::optional<CoaxialCore> core = coaxial_core(lens);
  if (!core) throw OptionsError("the poly model cannot fit this lens: " + LensFit::why_not_fittable(lens).value_or("no coaxial core"));
  CorePlacement placement;
  placement.first = core->first;
  // The frames as the exact model's tracer places them (its image plane at the camera's sensor).
  const LensFrames frames = surface_frames(lens, camera.z_sensor_mm() - lens.last_vertex_z_mm());
  placement.core = frames.surfaces[core->first];
  const SurfaceFrame& sensor = frames.image;
  placement.core_in_sensor.axes = sensor.axes.transpose() * placement.core.axes;
  placement.core_in_sensor.origin_mm = sensor.to_local(placement.core.origin_mm);
  const bool axis_own = placement.core.axes.isIdentity(0.0) && placement.core.origin_mm.isZero(0.0) &&
                        sensor.axes.isIdentity(0.0) && sensor.origin_mm.head<2>().isZero(0.0);
  placement.moved = !axis_own;
  return placement;
}

double CorePlacement::frame_reach_mm(const Camera& camera) const {
  const double w = camera.frame().width_px(), h = camera.frame().height_px();
  double reach = 0.0;
  for (const PixelPoint corner : {PixelPoint{0.0, 0.0}, PixelPoint{w, 0.0}, PixelPoint{0.0, h}, PixelPoint{w, h}}) {
    const auto [x, y] = camera.sensor_point_mm(corner);
    // On the core's axis: a tilt turns the sensor by a few degrees, a shift moves the frame across the image circle.
    const Eigen::Vector3d in_core = core_in_sensor.to_local(Eigen::Vector3d(x, y, 0.0));
    reach = std::max(reach, std::hypot(in_core.x(), in_core.y()));
  }
  return reach;
}

PolyModel::PolyModel(const Camera& camera, std::shared_ptr<const LensFit> fit)
    : RayModel(camera), fit_(std::move(fit)), placement_(CorePlacement::of(camera)) {
  const Prescription& lens = *camera.lens();
  fit_->check_matches(lens);
  const ParaxialSystem p(lens);
  stop_radius_mm_ = lens.surfaces[static_cast<std::size_t>(p.stop_surface() - 1)].semi_diameter_mm.value_or(0.0);
  // The fit numbers the core's surfaces.
  const int core_stop = p.stop_surface() - static_cast<int>(placement_.first);
  if (core_stop != fit_->stop_surface()) {
    throw OptionsError("the fit's stop is surface " + std::to_string(fit_->stop_surface()) + " of the fitted core, the camera's surface " +
                       std::to_string(core_stop));
  }
  if (stop_radius_mm_ > fit_->stop_radius_mm() * (1.0 + 1e-9)) {
    throw OptionsError("f/" + format_number(camera.f_number()) + " opens the stop to " + format_number(stop_radius_mm_) +
                       " mm, wider than the " + format_number(fit_->stop_radius_mm()) + " mm the fit covers");
  }
  // The frame's corner on the fit's sensor plane (the camera's sensor sits elsewhere when it focuses
  // closer; the margin of the default image radius covers that).
  const double half_diagonal_mm = placement_.frame_reach_mm(camera);
  if (half_diagonal_mm > fit_->image_radius_mm()) {
    throw OptionsError("the fit covers the sensor out to " + format_number(fit_->image_radius_mm()) +
                       " mm from the axis; this frame reaches " + format_number(half_diagonal_mm) +
                       " mm: fit again with a larger --image-radius");
  }
  if (camera.min_wavelength_nm() < fit_->options().min_wavelength_nm - 1e-9 ||
      camera.max_wavelength_nm() > fit_->options().max_wavelength_nm + 1e-9) {
    throw OptionsError("the fit covers " + format_number(fit_->options().min_wavelength_nm) + "-" +
                       format_number(fit_->options().max_wavelength_nm) + " nm, the renderer needs " +
                       format_number(camera.min_wavelength_nm()) + "-" + format_number(camera.max_wavelength_nm()) + " nm");
  }
  normalisation_ = weight_normalisation_for(camera, [this](auto&&... a) { map_raw(a...); });
  unaimed_ = 0;  // the count is of the caller's rays
}

double PolyModel::outer_solid_angle(const ScenePoint& point, double z_perspective_mm, double x_mm, double y_mm) const {
  double dz_dx = 0.0, dz_dy = 0.0;
  const double sag = fit_->front_sag(x_mm, y_mm, dz_dx, dz_dy).value_or(0.0);
  return patch_solid_angle(point, z_perspective_mm, x_mm, y_mm, sag, dz_dx, dz_dy);
}

void PolyModel::map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                    std::span<SensorHit> hits) const {
  map_raw(point, wavelength_nm, pupil, hits);
  normalisation_.apply(wavelength_nm, hits);
}

void PolyModel::map_raw(const ScenePoint& camera_point, double wavelength_nm, std::span<const PupilPoint> pupil,
                        std::span<SensorHit> hits) const {
  // The scene point in the core's frame. For a lens that is its own core the camera's description as it
  // is; for a tilt-shift lens the point moved into the turned core's frame, described from the core's
  // vertex: w P = (tan_x, tan_y, w z_persp - 1) (LensFit::outer_line) taken there and scaled back to
  // that form, s = -1 / its z. The weight's cos theta and depth squared (patch_solid_angle) are then the
  // core's; `to_camera_weight` turns them back into the camera's: the ratio of the cosines and s^2.
  ScenePoint point = camera_point;
  ObjectPoint object{point.tan_x, point.tan_y, point.inverse_depth_per_mm, camera_.z_perspective_mm()};
  double to_camera_weight = 1.0;
  if (placement_.moved) {
    const double w = camera_point.inverse_depth_per_mm;
    const Eigen::Vector3d h = placement_.core.axes.transpose() *
                              (Eigen::Vector3d(camera_point.tan_x, camera_point.tan_y, w * camera_.z_perspective_mm() - 1.0) -
                               w * placement_.core.origin_mm);
    if (!(h.z() < 0.0)) {  // not in front of the core
      for (auto& hit : hits) hit = {};
      return;
    }
    const double s = -1.0 / h.z();
    point = ScenePoint{s * h.x(), s * h.y(), s * w};
    object = ObjectPoint{point.tan_x, point.tan_y, point.inverse_depth_per_mm, 0.0};
    to_camera_weight = s * s * std::sqrt((1.0 + point.tan_x * point.tan_x + point.tan_y * point.tan_y) /
                                         (1.0 + camera_point.tan_x * camera_point.tan_x + camera_point.tan_y * camera_point.tan_y));
  }
  const double dz_sensor = camera_.z_sensor_mm() - fit_->sensor_plane_z_mm();
  // Newton for the beam's centre gives the Jacobian of stop position in outer position; every pupil
  // point then iterates with that fixed Jacobian (the chord method, as the exact model does with its
  // affine map), starting from the centre solution moved by the Jacobian's inverse: the stop map is
  // nearly affine across one beam, so a few cheap evaluations replace a Jacobian per step.
  const double tolerance_mm = kAimTolerance * stop_radius_mm_;
  const FitAim centre = fit_->aim_from_object(object, 0.0, 0.0, wavelength_nm, std::nullopt, {tolerance_mm, 20});
  const auto& j = centre.jacobian;
  const double det = j[0] * j[3] - j[1] * j[2];
  if (!centre.converged || !(std::abs(det) > 0.0)) {
    for (auto& hit : hits) hit = {};
    unaimed_.fetch_add(hits.size(), std::memory_order_relaxed);
    return;
  }
  const std::array<double, 4> inverse{j[3] / det, -j[1] / det, -j[2] / det, j[0] / det};
  // Outer-pupil area (dx dy on surface 1) per unit stop area across this beam, for the rays'
  // radiometric weights: the solid angle of that element of surface 1 seen from the point.
  const double outer_area = to_camera_weight / std::abs(det);
  const double z_persp = object.origin_z_mm;
  // The chord steps of one pupil point: at most kMaxChordEvaluations evaluations of the fit, full steps.
  constexpr int kMaxChordEvaluations = 12;
  RootSolver2dOptions chord;
  chord.jacobian = JacobianSource::Fixed;
  chord.line_search = false;
  chord.tolerance = tolerance_mm;
  chord.max_iterations = kMaxChordEvaluations - 1;
  const RootSolver2d chord_solver(chord);
  // As in the exact model: each pupil point starts from its affine guess moved by the correction its
  // predecessor (a neighbour, in a pupil mesh) needed.
  double carried_x = 0.0, carried_y = 0.0;
  for (std::size_t i = 0; i < pupil.size(); ++i) {
    const double sx = pupil[i].x * stop_radius_mm_, sy = pupil[i].y * stop_radius_mm_;
    const Vector2 guess{centre.ray.x_mm + inverse[0] * sx + inverse[1] * sy, centre.ray.y_mm + inverse[2] * sx + inverse[3] * sy};
    Vector2 on_outer{guess[0] + carried_x, guess[1] + carried_y};
    auto miss = [&](const Vector2& u, Vector2& r, Matrix2*) {
      const auto at = fit_->stop_from_object(object, u[0], u[1], wavelength_nm);
      if (!at) return false;
      r = {(*at)[0] - sx, (*at)[1] - sy};
      return true;
    };
    const bool aimed = chord_solver.solve(miss, on_outer, &j).converged();
    double x = on_outer[0], y = on_outer[1];
    if (!aimed) {
      // Far from the centre the chord method may stall: full Newton from its last point.
      const FitAim aim = fit_->aim_from_object(object, sx, sy, wavelength_nm, std::array<double, 2>{x, y},
                                               {tolerance_mm, 20});
      if (!aim.converged) {
        hits[i] = {};
        unaimed_.fetch_add(1, std::memory_order_relaxed);
        carried_x = carried_y = 0.0;
        continue;
      }
      x = aim.ray.x_mm;
      y = aim.ray.y_mm;
    }
    carried_x = x - guess[0];
    carried_y = y - guess[1];
    const std::optional<PlaneRay> outer = fit_->outer_ray_from_object(object, x, y);
    if (!outer) {
      hits[i] = {};
      continue;
    }
    // The stop as wide as the aiming tolerance may put a rim ray outside it (exact_model.cpp).
    const FitTrace t = fit_->from_outer(*outer, wavelength_nm, stop_radius_mm_ * (1.0 + kStopEdgeTolerance));
    const double dz = std::sqrt(std::max(1e-12, 1.0 - t.ray.dx * t.ray.dx - t.ray.dy * t.ray.dy));
    const double weight = outer_area * outer_solid_angle(point, z_persp, x, y);
    if (!placement_.moved) {
      hits[i] = SensorHit{t.ray.x_mm + t.ray.dx / dz * dz_sensor, t.ray.y_mm + t.ray.dy / dz * dz_sensor, t.passes, true,
                          weight, t.clearance};
      continue;
    }
    // From the fit's sensor plane in the core's frame, in a straight line (air) to the camera's sensor.
    const Eigen::Vector3d from = placement_.core_in_sensor.to_global(Eigen::Vector3d(t.ray.x_mm, t.ray.y_mm, fit_->sensor_plane_z_mm()));
    const Eigen::Vector3d along = placement_.core_in_sensor.axes * Eigen::Vector3d(t.ray.dx, t.ray.dy, dz);
    if (!(along.z() > 0.0)) {
      hits[i] = {};
      continue;
    }
    const double to_sensor = -from.z() / along.z();
    hits[i] = SensorHit{from.x() + along.x() * to_sensor, from.y() + along.y() * to_sensor, t.passes, true, weight, t.clearance};
  }
}

}  // namespace lensmith::camera_detail

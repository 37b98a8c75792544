// The exact model: for each scene point, a ray to every requested point of the aperture stop,
// traced through the prescription onto the sensor. Aiming: three unclipped traces from the scene
// point give the affine map from entrance-pupil-plane targets to stop points; each pupil point's
// target is its inverse image, refined by Newton steps with that Jacobian until the ray crosses the
// stop within 1e-4 of its radius; the final trace clips at every clear aperture (vignetting).
#include <algorithm>
#include <cmath>
#include <vector>

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
    r.direction = (Eigen::Vector3d(target_x, target_y, target_z) - r.position_mm).normalized();
  } else {
    // Light from a point infinitely far along +tangents travels along -tangents.
    r.direction = Eigen::Vector3d(-p.tan_x, -p.tan_y, 1.0).normalized();
    const Eigen::Vector3d target(target_x, target_y, target_z);
    r.position_mm = target + r.direction * ((start_z_mm - target_z) / r.direction.z());
  }
  return r;
}

}  // namespace

ExactModel::ExactModel(const Camera& camera) : RayModel(camera) {
  const Prescription& lens = *camera.lens();
  TracerOptions clipped;
  clipped.image_distance_mm = camera.z_sensor_mm() - lens.last_vertex_z_mm();
  clipped_ = std::make_shared<SequentialTracer>(lens, clipped);
  TracerOptions free = clipped;
  free.clip_apertures = false;
  free_ = std::make_shared<SequentialTracer>(lens, free);
  // The stop Camera::from_lens sized to the f-number: the one ParaxialSystem finds.
  const ParaxialSystem p(lens);
  stop_surface_ = p.stop_surface();
  stop_radius_mm_ = lens.surfaces[static_cast<std::size_t>(stop_surface_ - 1)].semi_diameter_mm.value_or(0.0);
  z_stop_mm_ = clipped_->vertex_z_mm(stop_surface_);
}

void ExactModel::map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                     std::span<SensorHit> hits) const {
  thread_local std::vector<SurfaceHit> path;
  const FirstOrderSample fo = camera_.first_order(wavelength_nm);
  const double z_target = fo.z_entrance_pupil_mm;
  const double r_target = fo.entrance_pupil_radius_mm;
  const double start_z = std::min(0.0, z_target) - 10.0 - r_target;
  const double z_persp = camera_.z_perspective_mm();
  const std::size_t stop_index = static_cast<std::size_t>(stop_surface_ - 1);

  // Stop point of the unclipped ray towards an entrance-pupil-plane target; false if it fails.
  auto stop_point = [&](double tx, double ty, double& sx, double& sy) {
    const Ray r = ray_towards(point, z_persp, tx, ty, z_target, wavelength_nm, start_z);
    free_->trace_forward(r, &path);
    if (path.size() <= stop_index) return false;
    sx = path[stop_index].point_mm.x();
    sy = path[stop_index].point_mm.y();
    return true;
  };

  // Affine map target -> stop point from the centre and two offsets at half the pupil radius.
  const double h = 0.5 * r_target;
  double s0x, s0y, s1x, s1y, s2x, s2y;
  if (!stop_point(0.0, 0.0, s0x, s0y) || !stop_point(h, 0.0, s1x, s1y) || !stop_point(0.0, h, s2x, s2y)) {
    for (auto& hit : hits) hit = {};
    return;
  }
  const double j11 = (s1x - s0x) / h, j21 = (s1y - s0y) / h, j12 = (s2x - s0x) / h, j22 = (s2y - s0y) / h;
  const double det = j11 * j22 - j12 * j21;
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) {
    for (auto& hit : hits) hit = {};
    return;
  }
  const double i11 = j22 / det, i12 = -j12 / det, i21 = -j21 / det, i22 = j11 / det;
  const double tolerance = 1e-4 * stop_radius_mm_;

  for (std::size_t i = 0; i < pupil.size(); ++i) {
    const double want_x = pupil[i].x * stop_radius_mm_, want_y = pupil[i].y * stop_radius_mm_;
    double tx = i11 * (want_x - s0x) + i12 * (want_y - s0y);
    double ty = i21 * (want_x - s0x) + i22 * (want_y - s0y);
    bool aimed = false;
    for (int iteration = 0; iteration < 4; ++iteration) {
      double sx, sy;
      if (!stop_point(tx, ty, sx, sy)) break;
      const double ex = want_x - sx, ey = want_y - sy;
      if (std::hypot(ex, ey) <= tolerance) {
        aimed = true;
        break;
      }
      tx += i11 * ex + i12 * ey;
      ty += i21 * ex + i22 * ey;
    }
    if (!aimed) {
      hits[i] = {};
      continue;
    }
    const Ray ray = ray_towards(point, z_persp, tx, ty, z_target, wavelength_nm, start_z);
    const TraceResult t = clipped_->trace_forward(ray);
    if (t.ok()) {
      hits[i] = SensorHit{t.ray.position_mm.x(), t.ray.position_mm.y(), true, true};
      continue;
    }
    // Stopped by a clear aperture: where it would have landed, for the edge of the beam.
    const TraceResult f = t.status == RayStatus::Vignetted ? free_->trace_forward(ray) : TraceResult{};
    hits[i] = f.ok() ? SensorHit{f.ray.position_mm.x(), f.ray.position_mm.y(), false, true} : SensorHit{};
  }
}

}  // namespace lensmith::camera_detail

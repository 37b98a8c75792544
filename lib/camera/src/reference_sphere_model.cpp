#include <algorithm>
#include <cmath>

#include "lensmith/core/units.h"
#include "model_implementations.h"

namespace lensmith::camera_detail {

ReferenceSphereModel::ReferenceSphereModel(RayModelKind kind, const Camera& camera, const RayModelOptions& options)
    : RayModel(camera), kind_(kind) {
  if (kind_ != RayModelKind::Seidel) return;
  // Coefficients over 64 wavelengths and object distances from the nearest scene depth to
  // infinity, evenly in 1 / distance, at the camera's f-number, normalised to the frame's corner.
  AberrationTableOptions t;
  const double nearest_object_mm =
      std::max(1.0, mm_from_m(options.nearest_depth_m) - camera.z_perspective_mm());
  t.object_distances_mm.clear();
  for (int k = 0; k < options.seidel_distance_samples; ++k) {
    const double inverse = (1.0 / nearest_object_mm) * k / (options.seidel_distance_samples - 1);
    t.object_distances_mm.push_back(distance_mm_from_inverse(inverse));
  }
  t.seidel.f_number = camera.f_number();
  const PinholeFrame& f = camera.frame();
  const double corner = std::hypot(0.5 * f.width_px(), 0.5 * f.height_px()) / f.focal_length_px();
  t.seidel.field_angle_deg = std::min(deg_from_rad(std::atan(corner)), 80.0);
  table_.emplace(*camera.lens(), t);
}

void ReferenceSphereModel::map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                               std::span<SensorHit> hits) const {
  const FirstOrderSample fo = camera_.first_order(wavelength_nm);
  const GaussianImage g = camera_.gaussian_image(point, fo);
  const double r_exit = fo.exit_pupil_radius_mm * camera_.pupil_orientation();
  const double z_exit = fo.z_exit_pupil_mm;
  const double z_sensor = camera_.z_sensor_mm();

  if (kind_ != RayModelKind::Seidel) {
    // Straight line from the exit-pupil point through the Gaussian image point to the sensor.
    const double t = (z_sensor - z_exit) / (g.z_mm - z_exit);
    for (std::size_t i = 0; i < pupil.size(); ++i) {
      const double px = r_exit * pupil[i].x, py = r_exit * pupil[i].y;
      hits[i] = {px + (g.x_mm - px) * t, py + (g.y_mm - py) * t, true, true};
    }
    return;
  }

  // Seidel: Born & Wolf's frame has y along the image point's direction from the axis (positive
  // field y0), x completing a right-handed pair; the pupil coordinate is the same in both pupils.
  // Depth is measured from the perspective centre, object distances from surface 1.
  const double object_distance_mm = distance_mm_from_inverse(point.inverse_depth_per_mm) - camera_.z_perspective_mm();
  const AberrationCoefficients c = table_->at(wavelength_nm, std::max(object_distance_mm, 1.0)).coefficients;
  const double t_len = std::hypot(point.tan_x, point.tan_y);
  double ey_x = 0.0, ey_y = 1.0;
  if (t_len > 0.0) {
    ey_x = -point.tan_x / t_len;  // the image lies opposite the object
    ey_y = -point.tan_y / t_len;
  }
  const double ex_x = ey_y, ex_y = -ey_x;
  const double y0 = c.max_field_tangent > 0.0 ? t_len / c.max_field_tangent : 0.0;
  const double B = c.B_mm, C = c.C_mm, D = c.D_mm, E = c.E_mm, F = c.F_mm;
  const double radius_sphere = std::sqrt(g.x_mm * g.x_mm + g.y_mm * g.y_mm + (g.z_mm - z_exit) * (g.z_mm - z_exit));
  for (std::size_t i = 0; i < pupil.size(); ++i) {
    // a = rho sin(theta), b = rho cos(theta) in Born & Wolf's frame (theta from +y).
    const double a = pupil[i].x * ex_x + pupil[i].y * ex_y;
    const double b = pupil[i].x * ey_x + pupil[i].y * ey_y;
    const double rho2 = a * a + b * b;
    // Marsicano eq. 3.35 expanded in a and b (no trigonometry per ray).
    const double dx = a * (B * rho2 - 2.0 * F * y0 * b + D * y0 * y0);
    const double dy = b * B * rho2 - F * y0 * (rho2 + 2.0 * b * b) + (2.0 * C + D) * y0 * y0 * b - E * y0 * y0 * y0;
    // Aberrated point P1 on the Gaussian image plane.
    const double p1x = g.x_mm + dx * ex_x + dy * ey_x;
    const double p1y = g.y_mm + dx * ex_y + dy * ey_y;
    // Q: where the line from the exit-pupil point to the Gaussian image point meets the reference
    // sphere (eq. 3.45), then the ray from Q through P1 to the sensor (eq. 3.46).
    const double ux = r_exit * pupil[i].x - g.x_mm, uy = r_exit * pupil[i].y - g.y_mm, uz = z_exit - g.z_mm;
    const double scale = radius_sphere / std::sqrt(ux * ux + uy * uy + uz * uz);
    const double qx = g.x_mm + ux * scale, qy = g.y_mm + uy * scale, qz = g.z_mm + uz * scale;
    const double d_x = p1x - qx, d_y = p1y - qy, d_z = g.z_mm - qz;
    const double s = (z_sensor - g.z_mm) / d_z;
    hits[i] = {p1x + d_x * s, p1y + d_y * s, true, true};
  }
}

}  // namespace lensmith::camera_detail

// Primary rays through a real lens for path tracers (lens_camera.h). The sampling and the weight
// follow pbrt-v4's RealisticCamera (GenerateRay: a point of the rear pupil's bound, the exact trace,
// cos^4 / D^2); lensmith normalises the weight by the on-axis beam so that images come out in the
// units of the scene's radiance, and aims at a disc around the paraxial exit pupil instead of
// pbrt's tabulated bounds of the rear element.
#include "lensmith/camera/lens_camera.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace lensmith {

namespace {

// The sampled disc's radius over the paraxial exit pupil's: the real beam (pupil aberration, a
// pupil that grows off axis) stays inside it for the shipped lenses (tests/scene, lens_render_test).
constexpr double kPupilEnlargement = 1.15;
// The default wavelengths: the bokeh renderer's range, every 10 nm.
constexpr double kDefaultMinNm = 380.0, kDefaultMaxNm = 780.0, kDefaultStepNm = 10.0;
// Polar midpoint grid of the on-axis irradiance integral (rings x sectors over the sampled disc):
// the beam's edge falls within 1/512 of the disc's radius.
constexpr int kAxisRings = 512;
constexpr int kAxisSectors = 8;

// cos^4 of the angle between `towards` (from the film point to a point of the exit-pupil plane) and
// the axis, over the squared axial distance D^2: the projected solid angle per unit area of that
// plane, cos(theta_film) cos(theta_pupil) / d^2 with d = D / cos(theta) (pbrt-v4 RealisticCamera).
double projected_solid_angle_density(const Eigen::Vector3d& towards) {
  const double d2 = towards.squaredNorm();
  const double cos2 = towards.z() * towards.z() / d2;
  return cos2 * cos2 / (towards.z() * towards.z());
}

// From a film point towards a point of the exit-pupil plane: a virtual exit pupil behind the film
// still sends the ray into the lens (towards -z).
Eigen::Vector3d into_lens(Eigen::Vector3d towards) { return towards.z() > 0.0 ? Eigen::Vector3d(-towards) : towards; }

}  // namespace

std::string CameraRay::to_string() const {
  std::ostringstream os;
  os << "CameraRay(origin (" << format_number(origin_m.x()) << ", " << format_number(origin_m.y()) << ", "
     << format_number(origin_m.z()) << ") m, direction (" << format_number(direction.x()) << ", " << format_number(direction.y())
     << ", " << format_number(direction.z()) << "), weight " << format_number(weight) << ")";
  return os.str();
}

LensCamera::LensCamera(const Camera& camera, std::span<const double> wavelengths_nm) : camera_(camera) {
  if (camera.is_thin_lens() || camera.lens() == nullptr) {
    throw OptionsError("LensCamera traces a prescription: this camera is an ideal thin lens");
  }
  TracerOptions options;
  options.image_distance_mm = camera.z_sensor_mm() - camera.lens()->last_vertex_z_mm();
  tracer_.emplace(*camera.lens(), options);
  make_nodes(wavelengths_nm);
}

LensCamera::LensCamera(const Camera& camera, std::shared_ptr<const LensFit> fit, std::span<const double> wavelengths_nm)
    : camera_(camera), fit_(std::move(fit)) {
  if (camera.is_thin_lens() || camera.lens() == nullptr) {
    throw OptionsError("LensCamera traces a prescription: this camera is an ideal thin lens");
  }
  if (!fit_) throw OptionsError("LensCamera: no fit given");
  const Prescription& lens = *camera.lens();
  fit_->check_matches(lens);
  const ParaxialSystem p(lens);
  stop_radius_mm_ = lens.surfaces[static_cast<std::size_t>(p.stop_surface() - 1)].semi_diameter_mm.value_or(0.0);
  if (stop_radius_mm_ > fit_->stop_radius_mm() * (1.0 + 1e-9)) {
    throw OptionsError("f/" + format_number(camera.f_number()) + " opens the stop to " + format_number(stop_radius_mm_) +
                       " mm, wider than the " + format_number(fit_->stop_radius_mm()) + " mm the fit covers");
  }
  make_nodes(wavelengths_nm);
}

void LensCamera::make_nodes(std::span<const double> wavelengths_nm) {
  std::vector<double> wavelengths(wavelengths_nm.begin(), wavelengths_nm.end());
  if (wavelengths.empty()) {
    for (double w = kDefaultMinNm; w <= kDefaultMaxNm + 1e-9; w += kDefaultStepNm) wavelengths.push_back(w);
  }
  std::sort(wavelengths.begin(), wavelengths.end());
  wavelengths.erase(std::unique(wavelengths.begin(), wavelengths.end()), wavelengths.end());
  const Eigen::Vector3d centre(0.0, 0.0, camera_.z_sensor_mm());
  for (double wavelength : wavelengths) {
    if (!(std::isfinite(wavelength) && wavelength > 0.0)) {
      throw OptionsError("LensCamera: wavelength " + format_number(wavelength) + " nm: must be finite and > 0");
    }
    const FirstOrderSample fo = camera_.first_order(wavelength);
    Node n;
    n.wavelength_nm = wavelength;
    n.z_exit_pupil_mm = fo.z_exit_pupil_mm;
    n.sampled_radius_mm = kPupilEnlargement * fo.exit_pupil_radius_mm;
    // Irradiance is radiance times the projected solid angle of the beam that reaches the film
    // point; normalised by the real on-axis beam's, at each wavelength.
    const double disc = n.sampled_radius_mm;
    double on_axis = 0.0;
    Eigen::Vector3d position, direction;
    for (int i = 0; i < kAxisRings; ++i) {
      const double r = disc * (i + 0.5) / kAxisRings;
      const double ring_cell = r * (disc / kAxisRings) * (2.0 * kPi / kAxisSectors);
      for (int j = 0; j < kAxisSectors; ++j) {
        const double phi = 2.0 * kPi * (j + 0.5) / kAxisSectors;
        const Eigen::Vector3d towards = into_lens(Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), n.z_exit_pupil_mm) - centre);
        if (!(towards.z() < 0.0)) continue;
        if (trace(centre, towards, wavelength, position, direction) == CameraRayFate::Passed) {
          on_axis += projected_solid_angle_density(towards) * ring_cell;
        }
      }
    }
    if (!(on_axis > 0.0)) {
      throw ComputationError("no ray from the centre of the sensor passes the lens at " + format_number(wavelength) +
                             " nm: the stop or a clear aperture closes the beam");
    }
    n.weight_scale = kPi * disc * disc / on_axis;
    nodes_.push_back(n);
  }
}

LensCamera::Node LensCamera::node_at(double wavelength_nm) const {
  if (nodes_.size() == 1 || wavelength_nm <= nodes_.front().wavelength_nm) return nodes_.front();
  if (wavelength_nm >= nodes_.back().wavelength_nm) return nodes_.back();
  const auto upper = std::upper_bound(nodes_.begin(), nodes_.end(), wavelength_nm,
                                      [](double w, const Node& n) { return w < n.wavelength_nm; });
  const Node& b = *upper;
  const Node& a = *(upper - 1);
  if (a.wavelength_nm == wavelength_nm) return a;
  const double t = (wavelength_nm - a.wavelength_nm) / (b.wavelength_nm - a.wavelength_nm);
  Node n;
  n.wavelength_nm = wavelength_nm;
  n.z_exit_pupil_mm = a.z_exit_pupil_mm + t * (b.z_exit_pupil_mm - a.z_exit_pupil_mm);
  n.sampled_radius_mm = a.sampled_radius_mm + t * (b.sampled_radius_mm - a.sampled_radius_mm);
  n.weight_scale = a.weight_scale + t * (b.weight_scale - a.weight_scale);
  return n;
}

CameraRayFate LensCamera::trace(const Eigen::Vector3d& on_sensor, const Eigen::Vector3d& towards, double wavelength_nm,
                                Eigen::Vector3d& position_mm, Eigen::Vector3d& direction) const {
  if (tracer_) {
    Ray ray;
    ray.position_mm = on_sensor;
    ray.direction = towards.normalized();
    ray.wavelength_nm = wavelength_nm;
    const TraceResult traced = tracer_->trace_backward(ray);
    if (!traced.ok()) return traced.status == RayStatus::Vignetted ? CameraRayFate::Vignetted : CameraRayFate::Failed;
    position_mm = traced.ray.position_mm;
    direction = traced.ray.direction;
    return CameraRayFate::Passed;
  }
  // The fit starts on its own sensor plane: the film ray carried there in a straight line (air).
  const Eigen::Vector3d travel = -towards.normalized();  // along the light, towards the image (+z)
  const double t = (fit_->sensor_plane_z_mm() - on_sensor.z()) / towards.z();
  PlaneRay sensor;
  sensor.x_mm = on_sensor.x() + t * towards.x();
  sensor.y_mm = on_sensor.y() + t * towards.y();
  sensor.dx = travel.x();
  sensor.dy = travel.y();
  const FitTrace f = fit_->from_sensor(sensor, wavelength_nm, stop_radius_mm_);
  if (!f.passes) return CameraRayFate::Vignetted;
  const double dz2 = 1.0 - f.ray.dx * f.ray.dx - f.ray.dy * f.ray.dy;
  const double r = std::hypot(f.ray.x_mm, f.ray.y_mm);
  if (!(dz2 > 0.0) || !std::isfinite(r)) return CameraRayFate::Failed;
  const double sag = camera_.lens()->surfaces.front().sag_mm(r);
  if (!std::isfinite(sag)) return CameraRayFate::Failed;
  position_mm = Eigen::Vector3d(f.ray.x_mm, f.ray.y_mm, sag);
  direction = Eigen::Vector3d(-f.ray.dx, -f.ray.dy, -std::sqrt(dz2));  // back out into the scene
  return CameraRayFate::Passed;
}

CameraRaySample LensCamera::sample_ray(double film_x_mm, double film_y_mm, double u, double v, double wavelength_nm) const {
  const Node node = node_at(wavelength_nm);
  const Eigen::Vector3d on_sensor(film_x_mm, film_y_mm, camera_.z_sensor_mm());
  const double r = node.sampled_radius_mm * std::sqrt(u);
  const double phi = 2.0 * kPi * v;
  const Eigen::Vector3d towards = into_lens(Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), node.z_exit_pupil_mm) - on_sensor);
  CameraRaySample out;
  if (!(towards.z() < 0.0)) return out;
  Eigen::Vector3d p, d;
  out.fate = trace(on_sensor, towards, wavelength_nm, p, d);
  if (!out.ok()) return out;
  // Lens frame -> camera frame: (x, y, z_perspective - z), directions (l, m, -n) (lens_render.h).
  out.ray.origin_m = Eigen::Vector3d(m_from_mm(p.x()), m_from_mm(p.y()), m_from_mm(camera_.z_perspective_mm() - p.z()));
  out.ray.direction = Eigen::Vector3d(d.x(), d.y(), -d.z()).normalized();
  out.ray.weight = node.weight_scale * projected_solid_angle_density(towards);
  return out;
}

std::optional<CameraRay> LensCamera::generate_ray(double film_x_mm, double film_y_mm, double u, double v, double wavelength_nm) const {
  const CameraRaySample s = sample_ray(film_x_mm, film_y_mm, u, v, wavelength_nm);
  if (!s.ok()) return std::nullopt;
  return s.ray;
}

std::array<double, 2> LensCamera::film_point_mm(double x_px, double y_px) const {
  return camera_.sensor_point_mm({x_px, y_px});
}

std::string LensCamera::to_string() const {
  std::ostringstream os;
  os << "LensCamera(" << (fit_ ? "polynomial fit" : "exact tracer") << ", " << nodes_.size() << " wavelengths "
     << format_number(nodes_.front().wavelength_nm) << "-" << format_number(nodes_.back().wavelength_nm) << " nm, f/"
     << format_rounded(camera_.f_number(), 3) << ")";
  return os.str();
}

}  // namespace lensmith

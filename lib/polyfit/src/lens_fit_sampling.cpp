// The beam a fit samples (lens_fit_stages.h): a point on the sensor and a point on the exit pupil, as
// pbrt-v4's RealisticCamera samples its rays, traced backward by the exact tracer without clipping;
// each candidate records where it crossed every surface and its uncoated Fresnel transmittance.
#include <cmath>

#include "lens_fit_stages.h"
#include "lensmith/core/number_parsing.h"
#include "lensmith/core/split_mix.h"
#include "lensmith/core/units.h"
#include "lensmith/trace/fresnel.h"

namespace lensmith::polyfit_detail {

namespace {

double uniform(std::uint64_t& state) { return static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53; }

TracerOptions unclipped_at_paraxial_focus() {
  TracerOptions o;
  o.image_plane = TracerOptions::ImagePlane::ParaxialFocus;
  o.clip_apertures = false;
  return o;
}

}  // namespace

RaySampler::RaySampler(const Prescription& lens, const LensFitOptions& options)
    : options_(options), tracer_(lens, unclipped_at_paraxial_focus()), paraxial_(lens) {
  image_radius_mm_ = options.image_radius_mm.value_or(LensFitOptions::kDefaultImageRadiusMm);
  if (sensor_z_mm() <= lens.vertex_z_mm(lens.surfaces.size() - 1)) {
    throw FitError("lens fit: the paraxial focus (z = " + format_number(sensor_z_mm()) +
                   " mm) is not behind the last surface: the sensor-side plane must lie in air after the lens");
  }
  const std::size_t stop_index = static_cast<std::size_t>(stop_surface() - 1);
  const double marginal_at_stop = std::abs(paraxial_.marginal_ray().rows[stop_index].y_mm);
  stop_radius_mm_ = std::max(lens.surfaces[stop_index].semi_diameter_mm.value_or(0.0), marginal_at_stop);
  // The stop a camera opens for this f-number (Camera::from_lens clips there), when wider.
  if (options.f_number) {
    stop_radius_mm_ = std::max(stop_radius_mm_, stop_opened_to_f_number(lens, *options.f_number).semi_diameter_mm);
  }
  double pupil_radius_mm = std::abs(paraxial_.exit_pupil().magnification) * stop_radius_mm_;
  if (!lens.is_rotationally_symmetric()) {
    // The x section's exit pupil may lie elsewhere and be another size (a rear anamorphic group): the
    // sampled disc on the y section's pupil plane also covers the cone from the axial image point
    // through the x section's pupil.
    ParaxialOptions x_section;
    x_section.section = Section::X;
    paraxial_x_.emplace(lens, x_section);
    const Pupil& px = paraxial_x_->exit_pupil();
    const double to_x = sensor_z_mm() - px.z_mm, to_y = sensor_z_mm() - paraxial_.exit_pupil().z_mm;
    if (to_x != 0.0) pupil_radius_mm = std::max(pupil_radius_mm, std::abs(px.magnification) * stop_radius_mm_ * std::abs(to_y / to_x));
  }
  sampled_pupil_radius_mm_ = options.pupil_margin * pupil_radius_mm;
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    const Surface& s = lens.surfaces[k];
    ClipSurface c{static_cast<int>(k + 1), k == stop_index ? stop_radius_mm_ : s.semi_diameter_mm.value_or(kInfinity), std::nullopt};
    if (k != stop_index && s.aperture) c.aperture = *s.aperture;
    apertures_.push_back(c);
  }
}

Candidate RaySampler::make(std::uint64_t stream, std::uint64_t index, std::vector<SurfaceHit>& path) const {
  std::uint64_t state = stream ^ (index * 0xD1B54A32D192ED03ull);
  Candidate c;
  const double rs = image_radius_mm_ * std::sqrt(uniform(state));
  const double ps = 2.0 * kPi * uniform(state);
  const double rp = sampled_pupil_radius_mm_ * std::sqrt(uniform(state));
  const double pp = 2.0 * kPi * uniform(state);
  c.wavelength_nm = options_.min_wavelength_nm + (options_.max_wavelength_nm - options_.min_wavelength_nm) * uniform(state);
  const Eigen::Vector3d on_sensor(rs * std::cos(ps), rs * std::sin(ps), sensor_z_mm());
  const Eigen::Vector3d on_pupil(rp * std::cos(pp), rp * std::sin(pp), paraxial_.exit_pupil().z_mm);
  // Light travels from the pupil point to the sensor (+z); a virtual exit pupil behind the sensor
  // reverses the difference.
  Eigen::Vector3d forward = (on_sensor - on_pupil).normalized();
  if (forward.z() < 0.0) forward = -forward;
  c.sensor = PlaneRay{on_sensor.x(), on_sensor.y(), forward.x(), forward.y()};
  Ray ray;
  ray.position_mm = on_sensor;
  ray.direction = -forward;
  ray.wavelength_nm = c.wavelength_nm;
  const TraceResult t = tracer_.trace_backward(ray, &path);
  if (!t.ok()) return c;
  const std::size_t surfaces = apertures_.size();
  c.hit_x.assign(surfaces, 0.0);
  c.hit_y.assign(surfaces, 0.0);
  c.in_domain = c.passes = true;
  // Backward through each surface: from the medium after it into the medium before it.
  c.transmittance = path_transmittance(tracer_, ray.direction, path, c.wavelength_nm, /*backward=*/true);
  for (const SurfaceHit& h : path) {
    const std::size_t k = static_cast<std::size_t>(h.surface - 1);
    c.hit_x[k] = h.point_mm.x();
    c.hit_y[k] = h.point_mm.y();
    const ClipSurface& a = apertures_[k];
    const double r = std::hypot(h.point_mm.x(), h.point_mm.y());
    c.passes = c.passes && a.clearance(h.point_mm.x(), h.point_mm.y()) >= 0.0;
    // The domain is the beam's outline: a ray in an obscuration's shadow stays in it (the clipping
    // near the shadow's edge needs the maps there).
    c.in_domain = c.in_domain && r <= options_.aperture_margin * (a.aperture ? a.aperture->outer_radius_mm() : a.semi_diameter_mm);
  }
  // The object-space ray, as light travels it, where it meets surface 1.
  const Eigen::Vector3d f = -t.ray.direction;
  c.outer = PlaneRay{t.ray.position_mm.x(), t.ray.position_mm.y(), f.x(), f.y()};
  return c;
}

std::uint64_t stream_of(std::uint64_t seed, Stream which) {
  switch (which) {
    case Stream::Training: return splitmix64(seed);
    case Stream::Test: {
      std::uint64_t s = seed ^ 0x5DEECE66Dull;
      return splitmix64(s) + 1;
    }
    case Stream::Speed: {
      std::uint64_t s = seed ^ 0x9E3779B97F4A7C15ull;
      return splitmix64(s) + 2;
    }
  }
  return 0;
}

}  // namespace lensmith::polyfit_detail

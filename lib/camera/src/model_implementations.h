// The ray models behind make_ray_model (private to the camera layer).
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "lensmith/core/units.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/seidel/aberration_table.h"
#include "lensmith/trace/sequential_tracer.h"

namespace lensmith::camera_detail {

// The unnormalised radiometric weight of a ray from scene point `p` through the point (x, y) of a
// plane normal to the axis at z_plane_mm (ray_model.h, SensorHit::weight): the pinhole framing's
// cos(theta) (the patch's area seen from the perspective centre grows as 1 / cos^3 theta while its
// solid angle per pixel shrinks as cos^3: z^2 cos theta is left) times z^2 times the solid angle
// per unit area of the plane at p, dz / d^3. Written in inverse depth w = 1 / z so that it stays
// finite for points at infinity (cos^3 theta there):
//   cos theta (1 + (z_plane - z_persp) w) / |(x w - tan_x, y w - tan_y, 1 + (z_plane - z_persp) w)|^3.
// On a curved surface z(x, y) through that point, per unit of dx dy, the element's normal
// (-dz/dx, -dz/dy, 1) replaces the axis: pass its slopes.
inline double patch_solid_angle(const ScenePoint& p, double z_perspective_mm, double x_mm, double y_mm, double z_plane_mm,
                                double dz_dx = 0.0, double dz_dy = 0.0) {
  const double w = p.inverse_depth_per_mm;
  const double dz = 1.0 + (z_plane_mm - z_perspective_mm) * w;
  const double ux = x_mm * w - p.tan_x, uy = y_mm * w - p.tan_y;
  const double d2 = ux * ux + uy * uy + dz * dz;
  const double cos_theta = 1.0 / std::sqrt(1.0 + p.tan_x * p.tan_x + p.tan_y * p.tan_y);
  return cos_theta * std::abs(dz - ux * dz_dx - uy * dz_dy) / (d2 * std::sqrt(d2));
}

// Mean of patch_solid_angle over a disc of radius a_mm centred on the axis at z_plane_mm, for the
// on-axis point at inverse depth w (1/mm): 2 (z/dz)^2 / (s (s + 1)) with s = sqrt(1 + (a/dz)^2),
// the closed form of (1 / pi a^2) integral of z^2 dz / (dz^2 + r^2)^(3/2) 2 pi r dr, written
// without cancellation for distant points.
inline double mean_axial_patch_solid_angle(double w, double z_perspective_mm, double a_mm, double z_plane_mm) {
  const double dz_w = 1.0 + (z_plane_mm - z_perspective_mm) * w;  // dz / z
  const double a_w = a_mm * w;                                     // a / z
  const double s = std::sqrt(1.0 + (a_w * a_w) / (dz_w * dz_w));
  return 2.0 / (dz_w * dz_w * s * (s + 1.0));
}

// Relative miss on the stop within which a ray aimed at a stop point counts as there, and the
// margin the stop gets in the clipping that decides whether it passes: a pupil point on the unit
// circle is on the stop's edge by definition, and must not be lost to the aiming's rounding.
inline constexpr double kAimTolerance = 1e-4;
inline constexpr double kStopEdgeTolerance = 2.0 * kAimTolerance;

// Wavelengths at which WeightNormalisation tabulates (the on-axis solid angle varies smoothly).
inline constexpr int kNormalisationWavelengths = 9;

// Per-wavelength normalisation of a model's raw weights: their mean over the unit pupil for the
// on-axis point of the focus plane, tabulated at evenly spaced wavelengths over the camera's range
// and interpolated linearly.
class WeightNormalisation {
 public:
  WeightNormalisation() = default;
  // raw_mean(wavelength_nm) computes the mean at one wavelength.
  template <typename RawMean>
  WeightNormalisation(double min_wavelength_nm, double max_wavelength_nm, int samples, const RawMean& raw_mean) {
    lo_ = min_wavelength_nm;
    hi_ = max_wavelength_nm;
    for (int i = 0; i < samples; ++i) means_.push_back(raw_mean(lo_ + (hi_ - lo_) * i / (samples - 1)));
  }
  // The raw weights of `hits` (map_raw at wavelength_nm) normalised.
  void apply(double wavelength_nm, std::span<SensorHit> hits) const {
    const double s = scale(wavelength_nm);
    for (SensorHit& h : hits) h.weight *= s;
  }
  // 1 / the interpolated mean.
  double scale(double wavelength_nm) const {
    if (means_.empty()) return 1.0;
    const double u = std::clamp((wavelength_nm - lo_) / (hi_ - lo_), 0.0, 1.0) * static_cast<double>(means_.size() - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(u), means_.size() - 2);
    const double t = u - static_cast<double>(i);
    return 1.0 / (means_[i] + (means_[i + 1] - means_[i]) * t);
  }

 private:
  double lo_ = 0.0, hi_ = 1.0;
  std::vector<double> means_;
};

// The mean raw weight of `map_raw` over a polar grid of the unit pupil for the on-axis point of the
// camera's focus plane, at one wavelength (rays that do not pass count 0: vignetting on the axis).
template <typename MapRaw>
double axial_mean_weight(const Camera& camera, double wavelength_nm, const MapRaw& map_raw) {
  constexpr int kRings = 64, kSectors = 16;  // fine near the rim, where a clear aperture may cut the beam
  std::vector<PupilPoint> pupil;
  std::vector<double> area;
  for (int i = 0; i < kRings; ++i) {
    const double r = (i + 0.5) / kRings;
    for (int j = 0; j < kSectors; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5) / kSectors;
      pupil.push_back({r * std::cos(phi), r * std::sin(phi)});
      area.push_back(r);  // polar cell area, up to a constant
    }
  }
  std::vector<SensorHit> hits(pupil.size());
  const ScenePoint axis{0.0, 0.0, inverse_per_mm(camera.focus_distance_mm())};
  map_raw(axis, wavelength_nm, pupil, hits);
  double sum = 0.0, total = 0.0;
  for (std::size_t k = 0; k < hits.size(); ++k) {
    total += area[k];
    if (hits[k].ok) sum += area[k] * hits[k].weight;
  }
  return sum / total;
}

// The normalisation of a model whose raw map (map_raw(point, wavelength_nm, pupil, hits)) sets
// unnormalised weights: axial_mean_weight at kNormalisationWavelengths over the camera's range.
template <typename MapRaw>
WeightNormalisation weight_normalisation_for(const Camera& camera, const MapRaw& map_raw) {
  return WeightNormalisation(camera.min_wavelength_nm(), camera.max_wavelength_nm(), kNormalisationWavelengths,
                             [&](double wavelength_nm) { return axial_mean_weight(camera, wavelength_nm, map_raw); });
}

// thin, paraxial and seidel: the ray from the exit-pupil point towards the Gaussian image point,
// through the aberrated image point for seidel (Asberg's construction with the Gaussian reference
// sphere centred on the Gaussian image point and passing through the exit-pupil centre).
class ReferenceSphereModel final : public RayModel {
 public:
  ReferenceSphereModel(RayModelKind kind, const Camera& camera, const RayModelOptions& options);
  RayModelKind kind() const override { return kind_; }
  bool affine_in_pupil() const override { return kind_ != RayModelKind::Seidel; }
  void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
           std::span<SensorHit> hits) const override;
  void clip_discs(const ScenePoint& point, std::vector<PupilDisc>& discs) const override;
  void map_passing(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                   std::span<SensorHit> hits) const override;

 private:
  // map() with or without the clearance of each ray (first-order vignetting).
  void map_with(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil, std::span<SensorHit> hits,
                bool clearance) const;
  // A clear aperture as the paraxial optics sees it: the height at its vertex plane of the paraxial
  // ray that crosses the entrance-pupil plane at height y with slope u is a y + b u (reference
  // wavelength); it passes while that height is at most `radius` (mm).
  struct ParaxialAperture {
    double a = 0.0;
    double b = 0.0;
    double radius_mm = 0.0;
  };

  RayModelKind kind_;
  std::optional<AberrationTable> table_;  // seidel only
  std::vector<ParaxialAperture> apertures_;  // paraxial and seidel: every clear aperture but the stop
  double z_entrance_pupil_mm_ = 0.0;          // reference wavelength
  double entrance_pupil_radius_mm_ = 0.0;
  double axial_passing_share_ = 1.0;          // of the pupil, on the axis at the focus distance
};

// exact: rays traced through the prescription (stop at the camera's f-number), aimed at the stop.
class ExactModel final : public RayModel {
 public:
  explicit ExactModel(const Camera& camera);
  RayModelKind kind() const override { return RayModelKind::Exact; }
  bool affine_in_pupil() const override { return false; }
  void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
           std::span<SensorHit> hits) const override;

 private:
  // map() without the normalisation of the weights.
  void map_raw(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil, std::span<SensorHit> hits) const;

  std::shared_ptr<const SequentialTracer> free_;     // no clipping: aiming and the final trace
  std::vector<std::pair<std::size_t, double>> apertures_;  // clipping surfaces: 0-based index, semi-diameter (mm)
  int stop_surface_ = 0;                             // 1-based
  double stop_radius_mm_ = 0.0;
  double z_stop_mm_ = 0.0;
  WeightNormalisation normalisation_;
};

// poly: a polynomial fit of the lens (lens_fit.h). Each pupil point is aimed by Newton steps on the
// fit's outer -> stop map from the scene point, then carried to the sensor by the outer -> sensor map
// and a straight line from the fit's sensor plane to the camera's; clipping by the fitted positions on
// the clear apertures and the stop at the camera's f-number.
class PolyModel final : public RayModel {
 public:
  PolyModel(const Camera& camera, std::shared_ptr<const LensFit> fit);
  RayModelKind kind() const override { return RayModelKind::Poly; }
  bool affine_in_pupil() const override { return false; }
  void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
           std::span<SensorHit> hits) const override;

 private:
  void map_raw(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil, std::span<SensorHit> hits) const;
  // patch_solid_angle of the element dx dy of surface 1 at (x, y) (mm).
  double outer_solid_angle(const ScenePoint& point, double z_perspective_mm, double x_mm, double y_mm) const;

  std::shared_ptr<const LensFit> fit_;
  double stop_radius_mm_ = 0.0;
  WeightNormalisation normalisation_;
};

}  // namespace lensmith::camera_detail

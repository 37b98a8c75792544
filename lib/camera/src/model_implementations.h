// The ray models behind make_ray_model (private to the camera layer).
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "lensmith/camera/ray_model.h"
#include "lensmith/core/units.h"
#include "lensmith/polyfit/lens_fit.h"
#include "lensmith/seidel/aberration_table.h"
#include "lensmith/trace/ray_aiming.h"
#include "lensmith/trace/sequential_tracer.h"
#include "lensmith/trace/surface_frames.h"

namespace lensmith::camera_detail {

// Whether a surface of `lens` carries a central obscuration (an aperture that stops the rays inside it):
// a mirror lens's secondary shadow, which the paraxial and Seidel models cannot clip at.
inline bool has_central_obscuration(const Prescription& lens) {
  return std::any_of(lens.surfaces.begin(), lens.surfaces.end(), [](const Surface& s) { return s.aperture && s.aperture->obscuration; });
}

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
// Traces the exact model may spend aiming one ray at its stop point (a Broyden quasi-Newton: the
// Sasian triplet's frame at 1.2 m needs at most 4, the Canon 35 mm f/1.8's bundled scene 99.99999 %
// within 4 and the rest within 9; a ray not aimed is lost).
inline constexpr int kAimIterations = 10;

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

// Born & Wolf's aberration vector at one field y0: its coefficients times the powers of y0 that
// go with them, mm. In these terms the vector (Marsicano 2023, eq. 3.35) at pupil point
// (a, b) = rho (sin t, cos t) is
//   dx = a (spherical rho^2 - 2 coma b + curvature)
//   dy = b spherical rho^2 - coma (rho^2 + 2 b^2) + (2 astigmatism + curvature) b - distortion.
struct FieldTerms {
  double spherical = 0.0;    // B
  double astigmatism = 0.0;  // C y0^2
  double curvature = 0.0;    // D y0^2
  double distortion = 0.0;   // E y0^3
  double coma = 0.0;         // F y0

  static FieldTerms at(const AberrationCoefficients& c, double y0) {
    return {c.B_mm, c.C_mm * y0 * y0, c.D_mm * y0 * y0, c.E_mm * y0 * y0 * y0, c.F_mm * y0};
  }
  double& operator[](int i) { return i == 0 ? spherical : i == 1 ? astigmatism : i == 2 ? curvature : i == 3 ? distortion : coma; }
  double operator[](int i) const { return const_cast<FieldTerms&>(*this)[i]; }
};

// Asberg's construction for one scene point at one wavelength (Marsicano 2023, sec. 3.10): the
// aberration vector moves the Gaussian image point G to P1 on the Gaussian image plane; the ray
// leaves the Gaussian reference sphere (centred on G, through the exit pupil's centre) where the line
// from the exit-pupil point to G meets it (eq. 3.45), and goes through P1 to the sensor (eq. 3.46).
// The sensor point is affine in the FieldTerms (the vector is linear in them and the ray's parameter
// at the sensor does not depend on it), which is what lets FittedAberrations fit them by linear
// least squares.
struct SeidelRayGeometry {
  GaussianImage g;
  double r_exit = 0.0;  // signed exit-pupil radius, mm (pupil orientation applied)
  double z_exit = 0.0;
  double z_sensor = 0.0;
  double radius_sphere = 0.0;
  // Born & Wolf's frame: y along the image point's direction from the axis, x completing a
  // right-handed pair; y0 the field in units of the coefficients' maximum field.
  double ex_x = 0.0, ex_y = 0.0, ey_x = 0.0, ey_y = 1.0;
  double y0 = 0.0;
  // The ray's parameter at the sensor is this times the distance from the exit-pupil point to G
  // (the same for every pupil point, so sensor_point needs no division).
  double sensor_per_length = 0.0;

  SeidelRayGeometry(const Camera& camera, const FirstOrderSample& fo, const ScenePoint& point, double max_field_tangent)
      : g(camera.gaussian_image(point, fo)),
        r_exit(fo.exit_pupil_radius_mm * camera.pupil_orientation()),
        z_exit(fo.z_exit_pupil_mm),
        z_sensor(camera.z_sensor_mm()) {
    radius_sphere = std::sqrt(g.x_mm * g.x_mm + g.y_mm * g.y_mm + (g.z_mm - z_exit) * (g.z_mm - z_exit));
    const double t_len = std::hypot(point.tan_x, point.tan_y);
    if (t_len > 0.0) {
      ey_x = -point.tan_x / t_len;  // the image lies opposite the object
      ey_y = -point.tan_y / t_len;
    }
    ex_x = ey_y;
    ex_y = -ey_x;
    y0 = max_field_tangent > 0.0 ? t_len / max_field_tangent : 0.0;
    sensor_per_length = -(z_sensor - g.z_mm) / ((z_exit - g.z_mm) * radius_sphere);
  }

  // Where the ray through normalised pupil point q meets the sensor (mm) with aberration terms t.
  void sensor_point(const PupilPoint& q, const FieldTerms& t, double& x_mm, double& y_mm) const {
    // a = rho sin(theta), b = rho cos(theta) in Born & Wolf's frame (theta from +y); the pupil
    // coordinate is the same in both pupils.
    const double a = q.x * ex_x + q.y * ex_y;
    const double b = q.x * ey_x + q.y * ey_y;
    const double rho2 = a * a + b * b;
    const double dx = a * (t.spherical * rho2 - 2.0 * t.coma * b + t.curvature);
    const double dy = b * t.spherical * rho2 - t.coma * (rho2 + 2.0 * b * b) + (2.0 * t.astigmatism + t.curvature) * b - t.distortion;
    const double p1x = g.x_mm + dx * ex_x + dy * ey_x;
    const double p1y = g.y_mm + dx * ex_y + dy * ey_y;
    // The sphere point Q = G + u R / L (u from G to the exit-pupil point, L its length) and the line
    // from Q through P1 meets the sensor at P1 + (P1 - Q) s, s = (z_sensor - G_z) / (G_z - Q_z)
    // = L sensor_per_length: so x = P1_x + sensor_per_length (L (P1_x - G_x) - R u_x).
    const double ux = r_exit * q.x - g.x_mm, uy = r_exit * q.y - g.y_mm, uz = z_exit - g.z_mm;
    const double length = std::sqrt(ux * ux + uy * uy + uz * uz);
    x_mm = p1x + sensor_per_length * (length * (p1x - g.x_mm) - radius_sphere * ux);
    y_mm = p1y + sensor_per_length * (length * (p1y - g.y_mm) - radius_sphere * uy);
  }
};

class ExactModel;

// The seidel model's aberration terms fitted to real rays (RayModelOptions::seidel_coefficients,
// fitted_aberrations.cpp says why and how): per object distance of the model's table, field and a
// few wavelengths, the least-squares FieldTerms of the exact model's rays (the sums' where a fit is
// not possible); and the ratio of the light the real lens passes (the exact model's weights summed
// over the rays that pass) to the model's own.
class FittedAberrations {
 public:
  // The model's own map (weights and first-order clipping), for the light ratio.
  using ModelMap = std::function<void(const ScenePoint&, double, std::span<const PupilPoint>, std::span<SensorHit>)>;
  // Fits `table` (made for `camera`'s lens at its f-number) against `exact` (the same camera).
  FittedAberrations(const Camera& camera, const ExactModel& exact, const AberrationTable& table, const ModelMap& model);
  // The fitted terms at this wavelength, object distance (mm, from surface 1) and field y0 (in the
  // table's units) into `terms`, and the light ratio there as the result: trilinear in wavelength,
  // inverse distance and field.
  double fitted_terms(double wavelength_nm, double object_distance_mm, double y0, FieldTerms& terms) const;

 private:
  std::vector<double> inverse_distances_per_mm_;  // ascending, the table's
  std::vector<double> wavelengths_nm_;            // ascending
  std::vector<double> fields_;                    // y0, ascending from 0
  std::vector<FieldTerms> terms_;                 // [distance][wavelength][field]
  std::vector<double> light_;                     // [distance][wavelength][field]
  const FieldTerms& at(std::size_t j, std::size_t n, std::size_t k) const {
    return terms_[(j * wavelengths_nm_.size() + n) * fields_.size() + k];
  }
};

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
  std::optional<FittedAberrations> fitted_;  // seidel with fitted coefficients
  std::vector<ParaxialAperture> apertures_;  // paraxial and seidel: every clear aperture but the stop
  double z_entrance_pupil_mm_ = 0.0;          // reference wavelength
  double entrance_pupil_radius_mm_ = 0.0;
  double axial_passing_share_ = 1.0;          // of the pupil, on the axis at the focus distance
  std::uint64_t id_ = 0;                      // this model's key in map_with's per-thread cache
};

// exact: rays traced through the prescription (stop at the camera's f-number), aimed at the stop.
class ExactModel final : public RayModel {
 public:
  explicit ExactModel(const Camera& camera);
  RayModelKind kind() const override { return RayModelKind::Exact; }
  bool affine_in_pupil() const override { return false; }
  void map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
           std::span<SensorHit> hits) const override;
  std::size_t unaimed_rays() const override { return unaimed_.load(std::memory_order_relaxed); }

 private:
  // map() without the normalisation of the weights.
  void map_raw(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil, std::span<SensorHit> hits) const;

  // The entrance-pupil-plane target (z_target_mm) of the ray from `point` that RayAimer (the exact
  // tracer's tested aiming, docs/trace.md) sends through stop point (x, y) mm; false when it fails.
  // The caller checks it by tracing, as it checks its own aims.
  bool aim_by_ray_aimer(const ScenePoint& point, double wavelength_nm, double want_x_mm, double want_y_mm, double z_target_mm,
                        double& target_x_mm, double& target_y_mm) const;

  std::shared_ptr<const SequentialTracer> free_;     // no clipping: aiming and the final trace
  std::shared_ptr<const RayAimer> aimer_;            // on free_, real-stop aiming: where the beam's own aim fails
  // Clipping surfaces, as a fit's (lens_fit.h): semi-diameter (mm; the stop's with its edge tolerance) or
  // an explicit aperture (a central obscuration).
  std::vector<ClipSurface> apertures_;
  std::vector<SurfaceFrame> frames_;  // where each surface lies (apertures clip in their surface's frame)
  SurfaceFrame stop_frame_;
  int stop_surface_ = 0;                             // 1-based
  double stop_radius_mm_ = 0.0;
  double z_stop_mm_ = 0.0;
  WeightNormalisation normalisation_;
  mutable std::atomic<std::size_t> unaimed_{0};
};

// Where a fit's coaxial core (LensFit: the lens without the coordinate breaks at its ends) lies in a
// camera: its surface 1's vertex and axes in the global frame of the lens (surface_frames), and the same
// frame seen from the camera's sensor plane (its vertex and axes in the sensor's frame, as the exact
// tracer places the sensor). For most lenses the core is the lens and both are the axis's own (`moved`
// false); a tilt-shift lens's core is turned or moved by the breaks before it.
struct CorePlacement {
  std::size_t first = 0;  // 0-based index in the camera's lens of the core's surface 1
  bool moved = false;     // the core or the sensor plane is turned or moved off the axis
  SurfaceFrame core;            // global
  SurfaceFrame core_in_sensor;  // in the sensor's frame
  // Throws OptionsError when the camera's lens has no coaxial core (LensFit::why_not_fittable).
  static CorePlacement of(const Camera& camera);
  // The farthest corner of the camera's frame from the core's axis, mm (on the sensor plane; the fit's
  // image radius must reach it).
  double frame_reach_mm(const Camera& camera) const;
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
  std::shared_ptr<const LensFit> fit() const override { return fit_; }
  std::size_t unaimed_rays() const override { return unaimed_.load(std::memory_order_relaxed); }
  // The fit's training rays pass the clear apertures enlarged by its aperture margin.
  double landing_clearance_limit() const override { return 1.0 - fit_->options().aperture_margin; }

 private:
  void map_raw(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil, std::span<SensorHit> hits) const;
  // patch_solid_angle of the element dx dy of surface 1 at (x, y) (mm).
  double outer_solid_angle(const ScenePoint& point, double z_perspective_mm, double x_mm, double y_mm) const;

  std::shared_ptr<const LensFit> fit_;
  CorePlacement placement_;
  double stop_radius_mm_ = 0.0;
  WeightNormalisation normalisation_;
  mutable std::atomic<std::size_t> unaimed_{0};
};

}  // namespace lensmith::camera_detail

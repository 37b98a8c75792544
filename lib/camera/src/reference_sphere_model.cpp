#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>

#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "model_implementations.h"

namespace lensmith::camera_detail {

namespace {
// Field angle of the chief ray traced to learn the apertures' chief-ray heights per unit slope
// (paraxial optics is linear: any small angle gives the same ratio).
constexpr double kChiefProbeAngleDeg = 1.0;

// Pupil points mapped per call of seidel_sensor_points: the renderer maps 9 to about 100 at a time.
constexpr std::size_t kRayChunk = 16;

// The Seidel rays' sensor points (mm) of `count` <= kRayChunk pupil points, into arrays: a loop
// the compiler vectorises across rays (the SensorHit records, with their flags, it cannot), built
// for AVX2+FMA too and chosen at load time, like SplatBuffer::add_polygon. The per-ray arithmetic
// was 3/4 of the Seidel model's time and 13 % of a 1080p Seidel render's.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void seidel_sensor_points(const SeidelRayGeometry& geometry, const FieldTerms& terms, const PupilPoint* __restrict pupil,
                          std::size_t count, double* __restrict x_mm, double* __restrict y_mm) {
  const SeidelRayGeometry g = geometry;  // copies: the loop reads them as registers, not through aliases
  const FieldTerms t = terms;
  for (std::size_t i = 0; i < count; ++i) g.sensor_point(pupil[i], t, x_mm[i], y_mm[i]);
}
}  // namespace

ReferenceSphereModel::ReferenceSphereModel(RayModelKind kind, const Camera& camera, const RayModelOptions& options)
    : RayModel(camera), kind_(kind) {
  static std::atomic<std::uint64_t> models{0};
  id_ = ++models;
  if (kind_ == RayModelKind::Thin) return;
  // First-order vignetting: any paraxial ray is a combination of the marginal ray of an object at
  // infinity (height h at the entrance pupil, slope 0) and a chief ray (height 0 there, slope u_c),
  // so its height at surface k is (y / h) y_marginal(k) + (u / u_c) y_chief(k).
  {
    Prescription probe = *camera.lens();
    probe.field = FieldSpec{FieldSpec::Kind::AngleDeg, {kChiefProbeAngleDeg}};
    ParaxialOptions po;
    po.wavelength_nm = camera.reference_wavelength_nm();
    po.object_distance_mm = kInfinity;
    const ParaxialSystem p(probe, po);
    const double h = 0.5 * p.entrance_pupil().diameter_mm;
    const ParaxialRayTable& chief = *p.chief_ray();
    z_entrance_pupil_mm_ = p.entrance_pupil().z_mm;
    entrance_pupil_radius_mm_ = h;
    for (std::size_t k = 0; k < probe.surfaces.size(); ++k) {
      const std::optional<double>& r = probe.surfaces[k].semi_diameter_mm;
      if (!r || !(*r > 0.0) || static_cast<int>(k) + 1 == p.stop_surface()) continue;
      apertures_.push_back({p.marginal_ray().rows[k].y_mm / h, chief.rows[k].y_mm / chief.object_slope, *r});
    }
  }
  // The share of the pupil that passes on the axis of the focus plane (discs centred there): the
  // weights are normalised by it too, so that the centre of a uniform surface in focus keeps its
  // radiance, as the exact model's and the ground truth's normalisations do.
  std::vector<PupilDisc> axial;
  clip_discs(ScenePoint{0.0, 0.0, inverse_per_mm(camera.focus_distance_mm())}, axial);
  for (const PupilDisc& d : axial) axial_passing_share_ = std::min(axial_passing_share_, d.radius * d.radius);
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
  if (options.seidel_coefficients == SeidelCoefficients::Fitted) {
    // The model's weights and clipping do not depend on its aberration terms: map() with the sums
    // gives the light the fit compares with the real lens's.
    fitted_.emplace(camera, ExactModel(camera), *table_,
                    [this](const ScenePoint& p, double wavelength_nm, std::span<const PupilPoint> pupil, std::span<SensorHit> hits) {
                      map_with(p, wavelength_nm, pupil, hits, true);
                    });
  }
}

void ReferenceSphereModel::clip_discs(const ScenePoint& point, std::vector<PupilDisc>& discs) const {
  discs.clear();
  // The ray from the point to the entrance-pupil point a p has the height y = a p there and the
  // slope u = (a p w - tan) / d, d = 1 + (z_EP - z_persp) w (inverse-depth form), so its height at
  // an aperture, a_k a p + b_k u, stays within R_k on the disc |p - c| <= rho of the pupil with
  // s = a (a_k + b_k w / d), c = (b_k / d) tan / s and rho = R_k / |s|.
  const double w = point.inverse_depth_per_mm;
  const double d = 1.0 + (z_entrance_pupil_mm_ - camera_.z_perspective_mm()) * w;
  const double inverse_d = 1.0 / d;  // one division per point, one per aperture (the renderer asks per pixel)
  for (const ParaxialAperture& k : apertures_) {
    const double scale = entrance_pupil_radius_mm_ * (k.a + k.b * w * inverse_d);
    if (!(std::abs(scale) > 0.0)) continue;
    const double inverse_scale = 1.0 / scale;
    const double shift = k.b * inverse_d * inverse_scale;
    const PupilDisc disc{shift * point.tan_x, shift * point.tan_y, k.radius_mm * std::abs(inverse_scale)};
    // Only discs that cut the unit pupil matter: |c| + 1 > rho.
    const double inner = disc.radius - 1.0;
    if (inner < 0.0 || disc.x * disc.x + disc.y * disc.y > inner * inner) discs.push_back(disc);
  }
  // A disc that holds another wholly cuts nothing the other does not: drop it (the apertures of
  // one element's two faces are often nested so).
  for (std::size_t j = 0; j < discs.size();) {
    bool redundant = false;
    for (std::size_t i = 0; i < discs.size() && !redundant; ++i) {
      if (i == j) continue;
      const double dx = discs[i].x - discs[j].x, dy = discs[i].y - discs[j].y;
      const double gap = discs[j].radius - discs[i].radius;
      // Strictly inside, or equal and earlier (so that one of two equal discs stays).
      redundant = gap >= 0.0 && dx * dx + dy * dy <= gap * gap && (gap > 0.0 || i < j);
    }
    if (redundant) {
      discs.erase(discs.begin() + static_cast<std::ptrdiff_t>(j));
    } else {
      ++j;
    }
  }
}

void ReferenceSphereModel::map(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                               std::span<SensorHit> hits) const {
  map_with(point, wavelength_nm, pupil, hits, true);
}

void ReferenceSphereModel::map_passing(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                                       std::span<SensorHit> hits) const {
  map_with(point, wavelength_nm, pupil, hits, false);
}

void ReferenceSphereModel::map_with(const ScenePoint& point, double wavelength_nm, std::span<const PupilPoint> pupil,
                                    std::span<SensorHit> hits, bool with_clearance) const {
  // Radiometric weights from the paraxial entrance pupil: the solid angle each pupil element
  // subtends at the scene point, relative to the on-axis point of the focus plane (SensorHit).
  // The ideal thin lens has none.
  const bool weighted = kind_ != RayModelKind::Thin;
  const double z_persp = camera_.z_perspective_mm();
  // The first-order data and the weights' scale at this wavelength: the renderer maps at a few
  // wavelengths only, one point after another, so this thread's last few are kept.
  struct AtWavelength {
    std::uint64_t model = 0;  // 0: empty
    double wavelength_nm = 0.0;
    FirstOrderSample fo;
    double weight_scale = 1.0;
  };
  constexpr std::size_t kKept = 4;
  thread_local std::array<AtWavelength, kKept> kept;
  thread_local std::size_t next_kept = 0;
  const AtWavelength* at = nullptr;
  for (const AtWavelength& k : kept) {
    if (k.model == id_ && k.wavelength_nm == wavelength_nm) at = &k;
  }
  if (at == nullptr) {
    AtWavelength& k = kept[next_kept];
    next_kept = (next_kept + 1) % kKept;
    k.model = id_;
    k.wavelength_nm = wavelength_nm;
    k.fo = camera_.first_order(wavelength_nm);
    k.weight_scale = weighted ? 1.0 / (mean_axial_patch_solid_angle(inverse_per_mm(camera_.focus_distance_mm()), z_persp,
                                                                    k.fo.entrance_pupil_radius_mm, k.fo.z_entrance_pupil_mm) *
                                       axial_passing_share_)
                              : 1.0;
    at = &k;
  }
  const FirstOrderSample fo = at->fo;  // copied: the slot is the thread's to reuse
  const double r_exit = fo.exit_pupil_radius_mm * camera_.pupil_orientation();
  const double z_exit = fo.z_exit_pupil_mm;
  const double z_sensor = camera_.z_sensor_mm();
  const double r_entrance = fo.entrance_pupil_radius_mm;
  const double weight_scale = at->weight_scale;
  // The weight varies across a pupil by its solid angle's cos^3 over a few degrees at most: a
  // plane through its values at the pupil's centre and at (1, 0) and (0, 1) is within 1e-4 of it
  // for every lens the renderer serves, at a third of the cost per ray.
  double w0 = 1.0, wx = 0.0, wy = 0.0;
  if (weighted) {
    const double z = fo.z_entrance_pupil_mm;
    w0 = weight_scale * patch_solid_angle(point, z_persp, 0.0, 0.0, z);
    wx = weight_scale * patch_solid_angle(point, z_persp, r_entrance, 0.0, z) - w0;
    wy = weight_scale * patch_solid_angle(point, z_persp, 0.0, r_entrance, z) - w0;
  }
  auto weight = [&](const PupilPoint& q) { return w0 + wx * q.x + wy * q.y; };

  // First-order clear-aperture vignetting (clip_discs): a ray passes inside every disc.
  thread_local std::vector<PupilDisc> discs;
  if (with_clearance) {
    clip_discs(point, discs);
  } else {
    discs.clear();
  }
  auto clearance = [&](const PupilPoint& q) { return disc_clearance(q, discs); };
  auto hit = [&](double x_mm, double y_mm, const PupilPoint& q) {
    const double c = clearance(q);
    return SensorHit{x_mm, y_mm, c >= 0.0, true, weight(q), c};
  };

  if (kind_ != RayModelKind::Seidel) {
    // Straight line from the exit-pupil point through the Gaussian image point to the sensor (the
    // Seidel branch's SeidelRayGeometry finds that point itself).
    const GaussianImage g = camera_.gaussian_image(point, fo);
    const double t = (z_sensor - z_exit) / (g.z_mm - z_exit);
    for (std::size_t i = 0; i < pupil.size(); ++i) {
      const double px = r_exit * pupil[i].x, py = r_exit * pupil[i].y;
      hits[i] = hit(px + (g.x_mm - px) * t, py + (g.y_mm - py) * t, pupil[i]);
    }
    return;
  }

  // Seidel: depth is measured from the perspective centre, object distances from surface 1.
  const double object_distance_mm = distance_mm_from_inverse(point.inverse_depth_per_mm) - camera_.z_perspective_mm();
  const AberrationCoefficients c = table_->coefficients_at(wavelength_nm, std::max(object_distance_mm, 1.0));
  const SeidelRayGeometry geometry(camera_, fo, point, c.max_field_tangent);
  FieldTerms terms = FieldTerms::at(c, geometry.y0);
  // Fitted: the real lens's terms, and its light relative to the first-order weights and clipping.
  const double light = fitted_ ? fitted_->fitted_terms(wavelength_nm, std::max(object_distance_mm, 1.0), geometry.y0, terms) : 1.0;
  std::array<double, kRayChunk> x_mm, y_mm;
  for (std::size_t start = 0; start < pupil.size(); start += kRayChunk) {
    const std::size_t count = std::min(kRayChunk, pupil.size() - start);
    seidel_sensor_points(geometry, terms, pupil.data() + start, count, x_mm.data(), y_mm.data());
    for (std::size_t k = 0; k < count; ++k) {
      SensorHit& h = hits[start + k];
      h = hit(x_mm[k], y_mm[k], pupil[start + k]);
      h.weight *= light;
    }
  }
}

}  // namespace lensmith::camera_detail

// First-order optics of a prescription at one wavelength: system matrix (Hecht, Optics, 5th ed.,
// sec. 6.4), cardinal points, stop and pupils, paraxial ray tables and the Lagrange invariant
// (Welford, Aberrations of Optical Systems, ch. 4; W. J. Smith, Modern Optical Engineering, ch. 2-3).
// Signs: lensmith/core/conventions.h.
#include "lensmith/paraxial/paraxial_system.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "lensmith/core/errors.h"
#include "paraxial_kernel.h"

namespace lensmith {

// ---------------------------------------------------------------------------------------------
// Kernel shared with ParaxialSpectralTable (paraxial_kernel.h).
namespace paraxial_detail {

KernelMatrices compose_matrices(std::span<const double> curvatures_per_mm, std::span<const double> thicknesses_mm,
                                std::span<const double> indices_after, double n_object, std::size_t stop_index) {
  KernelMatrices out;
  SystemMatrix a;  // identity: the running product, restarted after the stop refraction
  SystemMatrix full;
  double n_before = n_object;
  const std::size_t count = curvatures_per_mm.size();
  for (std::size_t k = 0; k < count; ++k) {
    // Refraction R = [[1, -P], [0, 1]], P = (n' - n) c, applied from the left.
    const double power = (indices_after[k] - n_before) * curvatures_per_mm[k];
    out.sum_abs_surface_power_per_mm += std::abs(power);
    if (k == stop_index) out.front = a;
    a.a11 -= power * a.a21;
    a.a12 -= power * a.a22;
    full.a11 -= power * full.a21;
    full.a12 -= power * full.a22;
    if (k == stop_index) a = SystemMatrix{};
    n_before = indices_after[k];
    if (k + 1 == count) break;
    // Transfer T = [[1, 0], [t / n, 1]] over the gap to the next vertex.
    const double reduced = thicknesses_mm[k] / n_before;
    a.a21 += reduced * a.a11;
    a.a22 += reduced * a.a12;
    full.a21 += reduced * full.a11;
    full.a22 += reduced * full.a12;
  }
  out.rear = a;
  out.system = full;
  return out;
}

std::vector<double> reflection_signs(const Prescription& lens) {
  std::vector<double> signs(lens.surfaces.size());
  double sign = 1.0;
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    if (lens.surfaces[k].mirror) sign = -sign;
    signs[k] = sign;
  }
  return signs;
}

CardinalPoints cardinal_points(const KernelMatrices& m, double n_object, double n_image, double z_last_mm) {
  const SystemMatrix& a = m.system;
  const double power = -a.a12;
  if (!(std::abs(power) > kAfocalRelativePower * m.sum_abs_surface_power_per_mm)) {
    std::ostringstream msg;
    msg << "afocal system: its power (" << (power == 0.0 ? 0.0 : power) << " 1/mm) is below " << kAfocalRelativePower
        << " of the sum of its surfaces' powers (" << m.sum_abs_surface_power_per_mm
        << " 1/mm); it has no focal points, principal points or focal length";
    throw ComputationError(msg.str());
  }
  CardinalPoints c;
  c.power_per_mm = power;
  const double f_front = n_object / power;  // P to F is -f_front
  const double f_rear = n_image / power;    // P' to F' is +f_rear
  // A ray leaving parallel crosses the axis at z_F = n a11 / a12 in front; a parallel ray entering
  // crosses it at -n' a22 / a12 behind the last vertex (Hecht 6.4; Welford 4.3).
  c.z_front_focal_mm = n_object * a.a11 / a.a12;
  c.z_rear_focal_mm = z_last_mm - n_image * a.a22 / a.a12;
  c.z_front_principal_mm = c.z_front_focal_mm + f_front;
  c.z_rear_principal_mm = c.z_rear_focal_mm - f_rear;
  // Nodal points: F N = f' and N' F' = f, so both sit (n' - n) / P beyond the principal points.
  c.z_front_nodal_mm = c.z_front_focal_mm + f_rear;
  c.z_rear_nodal_mm = c.z_rear_focal_mm - f_front;
  return c;
}

PupilImages pupil_images(const KernelMatrices& m, double n_object, double n_image, double z_last_mm) {
  PupilImages p;
  // Entrance pupil: the ray through the stop centre, traced back, crosses the axis at
  // z = n m21 / m22; an object of height h in that plane lands on the stop at m22 h (det = 1).
  p.z_entrance_mm = n_object * m.front.a21 / m.front.a22;
  p.entrance_magnification = 1.0 / m.front.a22;
  // Exit pupil: the ray from the stop centre leaves the last vertex with n'u' = r11, y = r21.
  p.z_exit_mm = z_last_mm - n_image * m.rear.a21 / m.rear.a11;
  p.exit_magnification = 1.0 / m.rear.a11;
  return p;
}

ImageConjugate image_conjugate(const SystemMatrix& a, double n_object, double n_image, double object_distance_mm) {
  ImageConjugate out;
  if (std::isinf(object_distance_mm)) {
    out.image_distance_mm = -n_image * a.a22 / a.a12;
    out.magnification = 0.0;
    return out;
  }
  // The axial ray with n u = n_object leaves with n'u' = a11 n + a12 d and height a21 n + a22 d
  // (scaled by 1/n); it meets the axis -y'/u' behind the last vertex.
  const double d = object_distance_mm;
  const double nu_image = a.a11 * n_object + a.a12 * d;
  const double y_image = a.a21 * n_object + a.a22 * d;
  if (!(std::abs(nu_image) > kAtInfinityRelative * (std::abs(a.a11 * n_object) + std::abs(a.a12 * d)))) {
    std::ostringstream msg;
    msg << "the image of an object at " << d
        << " mm in front of surface 1 lies at infinity (the object is in the front focal plane)";
    throw ComputationError(msg.str());
  }
  out.image_distance_mm = -n_image * y_image / nu_image;
  out.magnification = n_object / nu_image;
  return out;
}

std::string format_fixed(double value, int decimals) {
  if (std::isinf(value)) return value > 0 ? "infinity" : "-infinity";
  if (std::isnan(value)) return "nan";
  if (std::abs(value) < 0.5 * std::pow(10.0, -decimals)) value = 0.0;
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string right_aligned(const std::string& text, std::size_t width) {
  if (text.size() >= width) return text;
  return std::string(width - text.size(), ' ') + text;
}

}  // namespace paraxial_detail

// ---------------------------------------------------------------------------------------------
namespace {

// An object-space telecentric lens's entrance pupil, at infinity, is put this far behind surface 1
// (mm): chief rays then leave the object at slopes of h / 1e12, 1e-11 mm of image height for a 10-mm
// field over 1 m, and every formula written for a finite pupil holds.
constexpr double kTelecentricPupilZ_mm = 1e12;

}  // namespace

namespace {

using paraxial_detail::CardinalPoints;
using paraxial_detail::KernelMatrices;

std::string number(double value, int decimals) { return paraxial_detail::format_fixed(value, decimals); }
std::string padded(const std::string& text, std::size_t width) { return paraxial_detail::right_aligned(text, width); }

std::string field(double value, int decimals, std::size_t width) { return padded(number(value, decimals), width); }

std::string label(const std::string& text, std::size_t width) {
  std::string s = text;
  if (s.size() < width) s.append(width - s.size(), ' ');
  return s;
}

// The unfolded indices after each surface (negative after an odd number of mirrors).
std::vector<double> indices_at(const Prescription& lens, double wavelength_nm) {
  std::vector<double> indices(lens.surfaces.size());
  const std::vector<double> signs = paraxial_detail::reflection_signs(lens);
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) indices[k] = signs[k] * lens.surfaces[k].medium.index(wavelength_nm);
  return indices;
}

// Traces a paraxial ray (Welford 4.2: n'u' = n u - y (n' - n) c, y+ = y + t u') and fills a table.
// `image_gap_mm` is the last vertex to the image plane where the image height is taken.
ParaxialRayTable trace_ray(std::span<const double> curvatures, std::span<const double> thicknesses,
                           std::span<const double> indices, double n_object, double object_distance_mm,
                           double object_slope, double object_height_mm, double y1_mm, double image_gap_mm) {
  ParaxialRayTable table;
  table.object_distance_mm = object_distance_mm;
  table.object_slope = object_slope;
  table.object_height_mm = object_height_mm;
  table.y1_mm = y1_mm;
  table.rows.reserve(curvatures.size());
  double y = y1_mm;
  double u = object_slope;
  double n = n_object;
  for (std::size_t k = 0; k < curvatures.size(); ++k) {
    const double n_after = indices[k];
    const double incidence = u + y * curvatures[k];
    const double u_after = (n * u - y * (n_after - n) * curvatures[k]) / n_after;
    table.rows.push_back(ParaxialRayRow{static_cast<int>(k) + 1, y, u_after, incidence, n_after});
    u = u_after;
    n = n_after;
    if (k + 1 < curvatures.size()) y += thicknesses[k] * u;
  }
  table.image_height_mm = y + image_gap_mm * u;
  return table;
}

// The stop when none is flagged: the surface whose clear semi-diameter is reached first by the axial
// beam (smallest semi_diameter / |y| along a marginal ray from the axial object point).
std::size_t find_limiting_surface(const Prescription& lens, std::span<const double> curvatures,
                                  std::span<const double> thicknesses, std::span<const double> indices,
                                  double n_object, double object_distance_mm) {
  const bool at_infinity = std::isinf(object_distance_mm);
  const ParaxialRayTable ray = trace_ray(curvatures, thicknesses, indices, n_object, object_distance_mm,
                                         at_infinity ? 0.0 : 1.0 / object_distance_mm, 0.0, 1.0, 0.0);
  std::optional<std::size_t> best;
  double best_ratio = kInfinity;
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    const auto& sd = lens.surfaces[k].semi_diameter_mm;
    const double height = std::abs(ray.rows[k].y_mm);
    if (!sd || height == 0.0) continue;
    const double ratio = *sd / height;
    if (ratio < best_ratio) {
      best_ratio = ratio;
      best = k;
    }
  }
  if (!best) {
    throw ComputationError(
        "cannot determine the aperture stop: no surface is flagged as stop and no surface the axial beam "
        "crosses has a semi-diameter; flag the stop or give semi-diameters");
  }
  return *best;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
void ParaxialOptions::validate() const {
  if (!std::isfinite(wavelength_nm) || (wavelength_nm != 0.0 && !(wavelength_nm > 100.0 && wavelength_nm < 20000.0))) {
    throw OptionsError("ParaxialOptions::wavelength_nm = " + number(wavelength_nm, 4) +
                       ": must be 0 (the primary wavelength) or in (100, 20000) nm");
  }
  if (object_distance_mm && !(*object_distance_mm > 0.0)) {
    throw OptionsError("ParaxialOptions::object_distance_mm = " + number(*object_distance_mm, 6) +
                       ": must be > 0 (+infinity for an object at infinity)");
  }
}

ParaxialSystem::ParaxialSystem(const Prescription& lens, const ParaxialOptions& options) {
  options.validate();
  lens.validate();

  const double primary_nm = lens.primary_wavelength_nm();
  wavelength_nm_ = options.wavelength_nm == 0.0 ? primary_nm : options.wavelength_nm;
  object_distance_mm_ = options.object_distance_mm.value_or(lens.object_distance_mm);
  const bool at_infinity = std::isinf(object_distance_mm_);

  const std::size_t count = lens.surfaces.size();
  curvatures_.resize(count);
  thicknesses_.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    curvatures_[k] = lens.surfaces[k].paraxial_curvature_per_mm(options.section);
    thicknesses_[k] = lens.surfaces[k].thickness_mm;
  }
  indices_ = indices_at(lens, wavelength_nm_);
  n_object_ = lens.object_medium.index(wavelength_nm_);
  n_image_ = indices_.back();
  z_last_mm_ = 0.0;
  for (std::size_t k = 0; k + 1 < count; ++k) z_last_mm_ += thicknesses_[k];

  // The stop, the aperture and the image plane are physical: found at the primary wavelength so
  // that every wavelength sees the same stop, EPD (for EPD and F/# specs) and sensor position.
  const bool is_primary = wavelength_nm_ == primary_nm;
  const std::vector<double> primary_indices = is_primary ? indices_ : indices_at(lens, primary_nm);
  const double n_object_primary = lens.object_medium.index(primary_nm);

  if (const auto flagged = lens.flagged_stop_index()) {
    stop_surface_ = static_cast<int>(*flagged) + 1;
    stop_flagged_ = true;
  } else {
    stop_surface_ = static_cast<int>(find_limiting_surface(lens, curvatures_, thicknesses_, primary_indices,
                                                           n_object_primary, object_distance_mm_)) + 1;
    stop_flagged_ = false;
  }
  const std::size_t stop_index = static_cast<std::size_t>(stop_surface_ - 1);
  stop_semi_diameter_mm_ = lens.surfaces[stop_index].semi_diameter_mm;

  const KernelMatrices m =
      paraxial_detail::compose_matrices(curvatures_, thicknesses_, indices_, n_object_, stop_index);
  matrix_ = m.system;
  // Throws ComputationError for an afocal system.
  const CardinalPoints cardinal = paraxial_detail::cardinal_points(m, n_object_, n_image_, z_last_mm_);
  z_front_focal_mm_ = cardinal.z_front_focal_mm;
  z_rear_focal_mm_ = cardinal.z_rear_focal_mm;
  z_front_principal_mm_ = cardinal.z_front_principal_mm;
  z_rear_principal_mm_ = cardinal.z_rear_principal_mm;
  z_front_nodal_mm_ = cardinal.z_front_nodal_mm;
  z_rear_nodal_mm_ = cardinal.z_rear_nodal_mm;
  paraxial_detail::PupilImages pupils = paraxial_detail::pupil_images(m, n_object_, n_image_, z_last_mm_);
  telecentric_ = lens.object_space_telecentric;
  mirrors_ = lens.has_mirrors();
  breaks_ignored_ = !lens.is_coaxial();
  if (telecentric_) pupils.z_entrance_mm = kTelecentricPupilZ_mm;
  if (!std::isfinite(pupils.z_entrance_mm)) {
    throw ComputationError("the entrance pupil lies at infinity (stop at the rear focal point of the surfaces "
                           "before it, object-space telecentric): the marginal and chief rays are undefined");
  }

  KernelMatrices primary_m = m;
  if (!is_primary) {
    primary_m = paraxial_detail::compose_matrices(curvatures_, thicknesses_, primary_indices, n_object_primary,
                                                  stop_index);
  }

  switch (lens.aperture.kind) {
    case ApertureSpec::Kind::EntrancePupilDiameter:
      epd_mm_ = lens.aperture.value;
      break;
    case ApertureSpec::Kind::ImageSpaceFNumber: {
      // OpticStudio's Image Space F/# is f'/EPD with f' = n'/P the image-space focal length (equal to
      // the EFL in air): an eye model (n' = 1.336) has f'/EPD 1.336 times its EFL/EPD.
      const double power = paraxial_detail::cardinal_points(primary_m, n_object_primary, primary_indices.back(),
                                                            z_last_mm_).power_per_mm;
      epd_mm_ = std::abs(primary_indices.back() / power) / lens.aperture.value;
      break;
    }
    case ApertureSpec::Kind::ParaxialWorkingFNumber: {
      // W = 1 / (2 n' |u'|): trace the marginal ray for a unit pupil radius (slopes scale with it).
      const paraxial_detail::PupilImages primary_pupils =
          paraxial_detail::pupil_images(primary_m, n_object_primary, primary_indices.back(), z_last_mm_);
      double unit_slope = 0.0;
      double start_height = 1.0;
      if (!at_infinity) {
        const double object_to_pupil = object_distance_mm_ + primary_pupils.z_entrance_mm;
        if (object_to_pupil == 0.0) throw ComputationError("the object plane coincides with the entrance pupil: no marginal ray");
        unit_slope = 1.0 / object_to_pupil;
        start_height = unit_slope * object_distance_mm_;
      }
      const ParaxialRayTable unit = trace_ray(curvatures_, thicknesses_, primary_indices, n_object_primary, object_distance_mm_,
                                              unit_slope, 0.0, start_height, thicknesses_.back());
      const double u_image = std::abs(unit.rows.back().u_after);
      if (!(u_image > 0.0)) throw ComputationError("the marginal ray leaves the lens parallel to the axis: no paraxial working F/#");
      epd_mm_ = 2.0 / (2.0 * std::abs(primary_indices.back()) * lens.aperture.value * u_image);
      break;
    }
    case ApertureSpec::Kind::ObjectSpaceNA:
    case ApertureSpec::Kind::ObjectConeAngleDeg: {
      // The ray from the axial object point to the edge of the paraxial entrance pupil makes the angle
      // theta with the axis: n sin(theta) = NA, or theta the cone angle.
      if (at_infinity) throw ComputationError("an object-space NA or cone angle needs a finite object distance");
      paraxial_detail::PupilImages primary_pupils =
          paraxial_detail::pupil_images(primary_m, n_object_primary, primary_indices.back(), z_last_mm_);
      if (lens.object_space_telecentric) primary_pupils.z_entrance_mm = kTelecentricPupilZ_mm;
      const double theta = lens.aperture.kind == ApertureSpec::Kind::ObjectSpaceNA
                               ? std::asin(std::min(1.0, lens.aperture.value / n_object_primary))
                               : rad_from_deg(lens.aperture.value);
      epd_mm_ = 2.0 * std::abs(object_distance_mm_ + primary_pupils.z_entrance_mm) * std::tan(theta);
      break;
    }
    case ApertureSpec::Kind::FloatByStop: {
      const auto& sd = lens.surfaces[stop_index].semi_diameter_mm;
      if (!sd) {
        throw ComputationError("the aperture floats by the stop (surface " + std::to_string(stop_surface_) +
                               ") but the stop has no semi-diameter");
      }
      epd_mm_ = 2.0 * *sd * std::abs(pupils.entrance_magnification);
      break;
    }
  }
  entrance_pupil_ = Pupil{pupils.z_entrance_mm, epd_mm_, pupils.entrance_magnification};
  exit_pupil_ = Pupil{pupils.z_exit_mm, epd_mm_ * std::abs(pupils.exit_magnification / pupils.entrance_magnification),
                      pupils.exit_magnification};

  const paraxial_detail::ImageConjugate image =
      paraxial_detail::image_conjugate(matrix_, n_object_, n_image_, object_distance_mm_);
  image_distance_mm_ = image.image_distance_mm;
  magnification_ = image.magnification;
  if (lens.image_at_paraxial_focus) {
    image_plane_distance_mm_ = is_primary ? image_distance_mm_
                                          : paraxial_detail::image_conjugate(primary_m.system, n_object_primary,
                                                                             primary_indices.back(),
                                                                             object_distance_mm_)
                                                .image_distance_mm;
  } else {
    image_plane_distance_mm_ = thicknesses_.back();
  }

  // Marginal ray: from the axial object point to the upper edge of the entrance pupil.
  const double pupil_radius = 0.5 * epd_mm_;
  const double z_ep = entrance_pupil_.z_mm;
  if (at_infinity) {
    marginal_ = trace_ray(curvatures_, thicknesses_, indices_, n_object_, object_distance_mm_, 0.0, 0.0,
                          pupil_radius, image_plane_distance_mm_);
  } else {
    const double object_to_pupil = object_distance_mm_ + z_ep;
    if (object_to_pupil == 0.0) {
      throw ComputationError("the object plane coincides with the entrance pupil: no marginal ray");
    }
    const double slope = pupil_radius / object_to_pupil;
    marginal_ = trace_ray(curvatures_, thicknesses_, indices_, n_object_, object_distance_mm_, slope, 0.0,
                          slope * object_distance_mm_, image_plane_distance_mm_);
  }
  if (lens.object_space_telecentric) {
    // The exit pupil is still the stop's image; the beam, set by the NA, fills it to the marginal ray.
    exit_pupil_.diameter_mm = 2.0 * std::abs(marginal_.rows[stop_index].y_mm * pupils.exit_magnification);
  }

  // Chief ray: from the edge of the field through the centre of the entrance pupil, rising in
  // object space for a positive field (conventions.h), so a positive object-height field puts the
  // object point at y = -h and a real image lands at y > 0.
  if (lens.field) {
    const double value = lens.field->max_value();
    // A ray through the EP centre with object-space slope s: height -s z_ep at surface 1 and
    // -s (d + z_ep) at a finite object plane.
    auto chief_with_slope = [&](double slope) {
      const double object_height = at_infinity ? 0.0 : -slope * (object_distance_mm_ + z_ep);
      return trace_ray(curvatures_, thicknesses_, indices_, n_object_, object_distance_mm_, slope, object_height,
                       -slope * z_ep, image_plane_distance_mm_);
    };
    double slope = 0.0;
    switch (lens.field->kind) {
      case FieldSpec::Kind::AngleDeg:
        slope = std::tan(rad_from_deg(value));
        field_description_ = number(value, 4) + " deg object-space angle";
        break;
      case FieldSpec::Kind::ObjectHeightMm: {
        if (at_infinity) {
          throw ComputationError("an object-height field needs a finite object distance");
        }
        const double object_to_pupil = object_distance_mm_ + z_ep;
        if (object_to_pupil == 0.0) {
          throw ComputationError("the object plane coincides with the entrance pupil: no chief ray");
        }
        slope = value / object_to_pupil;
        field_description_ = number(value, 4) + " mm object height (object point at y = -" + number(value, 4) + ")";
        break;
      }
      case FieldSpec::Kind::RealImageHeightMm:
        throw ComputationError("the field is given as real image heights: only ray tracing finds the object points "
                               "(resolve_real_image_height_field in lensmith/trace/ray_aiming.h)");
      case FieldSpec::Kind::ImageHeightMm: {
        // The chief ray is linear in its slope: trace a unit slope to the paraxial image and scale.
        const ParaxialRayTable unit = chief_with_slope(1.0);
        const double landing = unit.rows.back().y_mm + image_distance_mm_ * unit.rows.back().u_after;
        if (landing == 0.0) {
          throw ComputationError("the chief ray meets the axis at the paraxial image: image-height field undefined");
        }
        slope = value / landing;
        field_description_ = number(value, 4) + " mm paraxial image height";
        break;
      }
    }
    chief_ = chief_with_slope(slope);
  }
}

double ParaxialSystem::efl_mm() const { return 1.0 / power_per_mm(); }
double ParaxialSystem::front_focal_length_mm() const { return n_object_ / power_per_mm(); }
double ParaxialSystem::rear_focal_length_mm() const { return n_image_ / power_per_mm(); }
double ParaxialSystem::z_front_focal_mm() const { return z_front_focal_mm_; }
double ParaxialSystem::z_rear_focal_mm() const { return z_rear_focal_mm_; }
double ParaxialSystem::bfl_mm() const { return z_rear_focal_mm_ - z_last_mm_; }
double ParaxialSystem::ffl_mm() const { return z_front_focal_mm_; }
double ParaxialSystem::z_front_principal_mm() const { return z_front_principal_mm_; }
double ParaxialSystem::z_rear_principal_mm() const { return z_rear_principal_mm_; }
double ParaxialSystem::z_front_nodal_mm() const { return z_front_nodal_mm_; }
double ParaxialSystem::z_rear_nodal_mm() const { return z_rear_nodal_mm_; }
double ParaxialSystem::z_last_surface_mm() const { return z_last_mm_; }
double ParaxialSystem::z_image_mm() const { return z_last_mm_ + image_distance_mm_; }

double ParaxialSystem::f_number() const { return std::abs(rear_focal_length_mm()) / epd_mm_; }

double ParaxialSystem::working_f_number() const { return 1.0 / (2.0 * image_space_na()); }

// |n'|: after an odd number of mirrors the unfolded index is negative.
double ParaxialSystem::image_space_na() const { return std::abs(n_image_) * std::abs(marginal_.rows.back().u_after); }
double ParaxialSystem::image_space_na_of_angle() const {
  return std::abs(n_image_) * std::sin(std::atan(std::abs(marginal_.rows.back().u_after)));
}

std::optional<double> ParaxialSystem::lagrange_invariant() const {
  if (!chief_) return std::nullopt;
  // Evaluated in object space at surface 1; conserved through the system.
  return n_object_ * (chief_->object_slope * marginal_.y1_mm - marginal_.object_slope * chief_->y1_mm);
}

double ParaxialSystem::focus_image_distance_mm(double object_distance_mm) const {
  if (!(object_distance_mm > 0.0)) {
    throw OptionsError("focus_image_distance_mm: object_distance_mm = " + number(object_distance_mm, 6) +
                       ": must be > 0 (+infinity for an object at infinity)");
  }
  return paraxial_detail::image_conjugate(matrix_, n_object_, n_image_, object_distance_mm).image_distance_mm;
}

// ---------------------------------------------------------------------------------------------
std::string SystemMatrix::to_string() const {
  std::ostringstream os;
  os.precision(10);
  os << "[[" << a11 << ", " << a12 << " 1/mm], [" << a21 << " mm, " << a22 << "]]";
  return os.str();
}

std::string ParaxialRayTable::to_string() const {
  std::ostringstream os;
  os << "  surf" << padded("y (mm)", 14) << padded("u", 14) << padded("i", 14) << padded("n'", 10) << '\n';
  os << "   obj" << (std::isinf(object_distance_mm) ? padded("at infinity", 14) : field(object_height_mm, 6, 14))
     << field(object_slope, 6, 14) << '\n';
  for (const ParaxialRayRow& row : rows) {
    os << padded(std::to_string(row.surface), 6) << field(row.y_mm, 6, 14) << field(row.u_after, 6, 14)
       << field(row.i, 6, 14) << field(row.n_after, 6, 10) << '\n';
  }
  os << "   img" << field(image_height_mm, 6, 14)
     << field(rows.empty() ? object_slope : rows.back().u_after, 6, 14) << '\n';
  return os.str();
}

std::string ParaxialSystem::to_string() const {
  constexpr std::size_t kLabel = 36;
  std::ostringstream os;
  auto line = [&](const std::string& name, const std::string& value, const std::string& note = {}) {
    os << label("  " + name, kLabel) << value << (note.empty() ? "" : "  (" + note + ")") << '\n';
  };
  os << "Paraxial (first-order) data at " << number(wavelength_nm_, 4) << " nm, object "
     << (std::isinf(object_distance_mm_) ? std::string("at infinity")
                                         : number(object_distance_mm_, 4) + " mm in front of surface 1")
     << '\n';
  os << "  z: mm from the vertex of surface 1, +z toward the image; last surface at z = " << number(z_last_mm_, 4)
     << " mm\n";
  if (mirrors_) os << "  mirrors unfolded: the index after a reflection is -n, thicknesses after one are negative\n";
  if (breaks_ignored_) {
    os << "  coordinate breaks ignored (as OpticStudio's paraxial trace by default): the surfaces taken on one axis, z along it\n";
  }
  os << "\n";

  line("System matrix (n u, y)", matrix_.to_string());
  line("Power", number(power_per_mm(), 8) + " 1/mm");
  line("Effective focal length EFL", number(efl_mm(), 4) + " mm", "1/P");
  line("Front focal length f", number(front_focal_length_mm(), 4) + " mm", "n/P, n = " + number(n_object_, 6));
  line("Rear focal length f'", number(rear_focal_length_mm(), 4) + " mm", "n'/P, n' = " + number(n_image_, 6));
  line("Back focal length BFL", number(bfl_mm(), 4) + " mm", "last surface to F'");
  line("Front focal distance FFL", number(ffl_mm(), 4) + " mm", "surface 1 to F");
  os << '\n';

  os << label("  Point", 28) << padded("z = from surf 1", 16) << padded("from last surf", 16) << "  (mm)\n";
  auto point = [&](const std::string& name, double z) {
    os << label("  " + name, 28) << field(z, 4, 16) << field(z - z_last_mm_, 4, 16) << '\n';
  };
  point("Front focal point F", z_front_focal_mm());
  point("Rear focal point F'", z_rear_focal_mm());
  point("Front principal point P", z_front_principal_mm());
  point("Rear principal point P'", z_rear_principal_mm());
  point("Front nodal point N", z_front_nodal_mm());
  point("Rear nodal point N'", z_rear_nodal_mm());
  if (telecentric_) {
    os << label("  Entrance pupil", 28) << "at infinity (object-space telecentric)\n";
  } else {
    point("Entrance pupil", entrance_pupil_.z_mm);
  }
  point("Exit pupil", exit_pupil_.z_mm);
  point("Paraxial image", z_image_mm());
  point("Image plane", z_last_mm_ + image_plane_distance_mm_);
  os << '\n';

  line("Aperture stop", "surface " + std::to_string(stop_surface_) +
                            (stop_semi_diameter_mm_ ? ", semi-diameter " + number(*stop_semi_diameter_mm_, 4) + " mm"
                                                    : std::string()),
       stop_flagged_ ? "flagged" : "found: limits the axial beam");
  if (!telecentric_) {
    line("Entrance pupil diameter EPD", number(entrance_pupil_.diameter_mm, 4) + " mm",
         "magnification " + number(entrance_pupil_.magnification, 5) + " of the stop");
  }
  line("Exit pupil diameter", number(exit_pupil_.diameter_mm, 4) + " mm",
       "magnification " + number(exit_pupil_.magnification, 5) + " of the stop");
  if (!telecentric_) line("F-number", number(f_number(), 4), std::abs(n_image_) == 1.0 ? "EFL/EPD" : "f'/EPD (image space)");
  line("Working F-number", number(working_f_number(), 4), "1/(2 n'|u'|), this object distance");
  line("Image-space NA", number(image_space_na(), 6), "n'|u'|; n' sin(atan|u'|) = " + number(image_space_na_of_angle(), 6) + " as OpticStudio prints it");
  line("Image distance", number(image_distance_mm_, 4) + " mm", "last surface to paraxial image");
  line("Image plane distance", number(image_plane_distance_mm_, 4) + " mm", "last surface to image plane");
  line("Magnification", number(magnification_, 6), std::isinf(object_distance_mm_) ? "object at infinity" : "");
  if (chief_) {
    line("Maximum field", field_description_);
    line("Chief-ray image height", number(chief_->image_height_mm, 4) + " mm", "at the image plane");
    line("Lagrange invariant H", number(*lagrange_invariant(), 6) + " mm", "n (u_chief y - u y_chief)");
  }

  os << "\nMarginal ray (axial object point to the edge of the entrance pupil; u after the surface, i = u + y c)\n"
     << marginal_.to_string();
  if (chief_) {
    os << "\nChief ray (maximum field, through the centre of the entrance pupil)\n" << chief_->to_string();
  } else {
    os << "\nChief ray: none (the prescription has no field)\n";
  }
  return os.str();
}

StopOpening stop_opened_to_f_number(const Prescription& lens, double f_number) {
  Prescription at_n = lens;
  at_n.aperture = ApertureSpec{ApertureSpec::Kind::ImageSpaceFNumber, f_number};
  const ParaxialSystem p(at_n);
  const int stop = p.stop_surface();
  return {stop, std::abs(p.marginal_ray().rows[static_cast<std::size_t>(stop - 1)].y_mm)};
}

}  // namespace lensmith

#include "lensmith/prescription/prescription.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "lensmith/core/errors.h"
#include "lensmith/core/number_parsing.h"

namespace lensmith {

namespace {

// The subject of an error about surface `index` (0-based).
ErrorSubject surface_subject(std::size_t index, std::string field = {}) {
  return ErrorSubject{static_cast<int>(index) + 1, std::move(field), -1};
}

[[noreturn]] void reject_surface(std::size_t index, const std::string& field, double value, const std::string& rule) {
  throw PrescriptionError(surface_subject(index, field),
                          "surface " + std::to_string(index + 1) + ": " + field + " = " + format_number(value) + ": " + rule);
}

// `shown` names the value in the message ("wavelengths_nm[2]"); `subject` is what a reader points at
// (the field `shown` without its index, when not given).
[[noreturn]] void reject_system(const std::string& shown, double value, const std::string& rule, ErrorSubject subject = {}) {
  if (subject.empty()) subject.field = shown;
  throw PrescriptionError(std::move(subject), shown + " = " + format_number(value) + ": " + rule);
}

// Wavelengths that optical glass catalogues can be meaningful for, nm.
constexpr double kMinWavelength_nm = 100.0;
constexpr double kMaxWavelength_nm = 20000.0;

}  // namespace

std::string ApertureSpec::to_string() const {
  switch (kind) {
    case Kind::EntrancePupilDiameter: return "entrance-pupil diameter " + format_number(value) + " mm";
    case Kind::ImageSpaceFNumber: return "image-space f/" + format_number(value);
    case Kind::FloatByStop: return "float by stop size";
    case Kind::ParaxialWorkingFNumber: return "paraxial working f/" + format_number(value);
    case Kind::ObjectSpaceNA: return "object-space NA " + format_number(value);
    case Kind::ObjectConeAngleDeg: return "object cone angle " + format_number(value) + " deg";
  }
  return "?";
}

double FieldSpec::max_value() const {
  double m = 0.0;
  for (double v : values) m = std::max(m, std::abs(v));
  return m;
}

VignettingFactors FieldSpec::vignetting_at(double value) const {
  if (vignetting.empty() || vignetting.size() != values.size()) return {};
  // The field points nearest below and above |value| by |field| (called per ray: no allocation).
  const double v = std::abs(value);
  std::size_t below = values.size(), above = values.size();
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double f = std::abs(values[i]);
    if (f <= v && (below == values.size() || f > std::abs(values[below]))) below = i;
    if (f >= v && (above == values.size() || f < std::abs(values[above]))) above = i;
  }
  if (below == values.size()) return vignetting[above];  // below the first point: held
  if (above == values.size()) return vignetting[below];  // beyond the last: held
  const double lo = std::abs(values[below]), hi = std::abs(values[above]);
  const double t = hi > lo ? (v - lo) / (hi - lo) : 0.0;
  const VignettingFactors& a = vignetting[below];
  const VignettingFactors& b = vignetting[above];
  auto mix = [t](double p, double q) { return p + t * (q - p); };
  return {mix(a.vdx, b.vdx), mix(a.vdy, b.vdy), mix(a.vcx, b.vcx), mix(a.vcy, b.vcy), mix(a.van_deg, b.van_deg)};
}

std::string FieldSpec::to_string() const {
  std::string unit = kind == Kind::AngleDeg         ? " deg (angle)"
                     : kind == Kind::ObjectHeightMm ? " mm (object height)"
                     : kind == Kind::ImageHeightMm  ? " mm (paraxial image height)"
                                                    : " mm (real image height)";
  std::string s;
  for (double v : values) s += (s.empty() ? "" : ", ") + format_number(v);
  return s + unit;
}

std::optional<std::size_t> Prescription::flagged_stop_index() const {
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    if (surfaces[i].is_stop) return i;
  }
  return std::nullopt;
}

double Prescription::vertex_z_mm(std::size_t surface_index) const {
  double z = 0.0;
  for (std::size_t i = 0; i < surface_index && i < surfaces.size(); ++i) z += surfaces[i].thickness_mm;
  return z;
}

int Prescription::mirror_count() const {
  return static_cast<int>(std::count_if(surfaces.begin(), surfaces.end(), [](const Surface& s) { return s.mirror; }));
}

bool Prescription::is_coaxial() const {
  return std::none_of(surfaces.begin(), surfaces.end(),
                      [](const Surface& s) { return s.is_coordinate_break() && !s.coordinate_break.is_identity(); });
}

bool Prescription::is_rotationally_symmetric() const {
  return is_coaxial() && std::all_of(surfaces.begin(), surfaces.end(), [](const Surface& s) { return s.is_rotationally_symmetric(); });
}

std::optional<std::string> Prescription::why_not_rotationally_symmetric() const {
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    const Surface& s = surfaces[i];
    if (s.is_coordinate_break() && !s.coordinate_break.is_identity()) {
      return "surface " + std::to_string(i + 1) + " is a coordinate break (" + s.coordinate_break.to_string() + ")";
    }
    if (!s.is_rotationally_symmetric()) return "surface " + std::to_string(i + 1) + " is " + std::string(lensmith::to_string(s.kind));
  }
  return std::nullopt;
}

bool Prescription::is_anamorphic() const {
  return std::any_of(surfaces.begin(), surfaces.end(), [](const Surface& s) { return !s.is_coordinate_break() && !s.is_rotationally_symmetric(); });
}

std::optional<std::string> Prescription::why_no_real_ray_aiming() const {
  if (auto why = why_not_rotationally_symmetric()) return why;
  if (has_mirrors()) return std::string("it has mirrors");
  return std::nullopt;
}

double Prescription::last_vertex_z_mm() const { return surfaces.empty() ? 0.0 : vertex_z_mm(surfaces.size() - 1); }

std::optional<CoaxialCore> coaxial_core(const Prescription& lens) {
  const auto is_break = [](const Surface& s) { return s.is_coordinate_break(); };
  const auto first = std::find_if_not(lens.surfaces.begin(), lens.surfaces.end(), is_break);
  if (first == lens.surfaces.end()) return std::nullopt;
  const auto last = std::find_if_not(lens.surfaces.rbegin(), lens.surfaces.rend(), is_break).base();  // one past
  if (std::any_of(first, last, [](const Surface& s) { return s.is_coordinate_break() && !s.coordinate_break.is_identity(); })) {
    return std::nullopt;
  }
  CoaxialCore core{static_cast<std::size_t>(first - lens.surfaces.begin()), lens};
  core.lens.surfaces.assign(first, last);
  double leading_mm = 0.0, trailing_mm = 0.0;
  for (auto s = lens.surfaces.begin(); s != first; ++s) leading_mm += s->thickness_mm;
  for (auto s = last; s != lens.surfaces.end(); ++s) trailing_mm += s->thickness_mm;
  if (std::isfinite(core.lens.object_distance_mm)) core.lens.object_distance_mm += leading_mm;
  core.lens.surfaces.back().thickness_mm += trailing_mm;
  return core;
}

Diagnostics Prescription::geometry_warnings() const {
  Diagnostics out;
  // Built member by member: GCC 12 at -O2 takes the aggregate's empty SourceLocation for
  // uninitialised (-Wmaybe-uninitialized, a false positive).
  auto warn = [&out](const std::string& message) {
    Diagnostic d;
    d.severity = Diagnostic::Severity::Warning;
    d.message = message;
    out.push_back(std::move(d));
  };
  // Tolerance for a crossing at the edge (mm): the rounding of thicknesses and radii in lens files.
  constexpr double kEdgeToleranceMm = 1e-4;
  // After an odd number of mirrors light travels toward -z and a glass's thickness is negative.
  double sense = 1.0;
  bool tilted = false;
  for (std::size_t i = 0; i + 1 < surfaces.size(); ++i) {
    const Surface& s = surfaces[i];
    const Surface& next = surfaces[i + 1];
    if (s.mirror) sense = -sense;
    tilted = tilted || (s.is_coordinate_break() && !s.coordinate_break.is_identity());
    if (s.is_coordinate_break() || next.is_coordinate_break() || tilted) continue;  // no common axis to measure along
    const bool glass = s.material.kind != MaterialSpec::Kind::Air;
    if (sense < 0.0) {
      if (glass && s.thickness_mm > 0.0) {
        warn("surface " + std::to_string(i + 1) + ": the glass after it (" + s.material.to_string() + ") follows an odd number of "
             "mirrors but has a positive thickness, " + format_rounded(s.thickness_mm, 4) + " mm: after a reflection thicknesses are negative");
      }
      continue;  // the edge check below assumes light travelling toward +z
    }
    if (glass && s.thickness_mm < 0.0) {
      warn("surface " + std::to_string(i + 1) + ": the glass after it (" + s.material.to_string() + ") has a negative centre thickness, " +
           format_rounded(s.thickness_mm, 4) + " mm: no element can be made so");
      continue;
    }
    if (!s.semi_diameter_mm || !next.semi_diameter_mm) continue;
    const double r = std::min(*s.semi_diameter_mm, *next.semi_diameter_mm);
    const double edge = s.thickness_mm + next.sag_mm(r) - s.sag_mm(r);
    if (std::isfinite(edge) && edge < -kEdgeToleranceMm && s.thickness_mm >= 0.0) {
      warn("surfaces " + std::to_string(i + 1) + " and " + std::to_string(i + 2) + " cross within their clear apertures: at r = " +
           format_rounded(r, 4) + " mm " + (glass ? "the element's edge thickness is " : "the air space between them is ") + format_rounded(edge, 3) +
           " mm (" + (glass ? "an element thinner than nothing at its rim" : "the elements overlap") + ")");
    }
  }
  return out;
}

void Prescription::validate() const {
  if (surfaces.empty()) throw PrescriptionError(ErrorSubject{0, "surfaces", -1}, "surfaces: a lens needs at least one surface");
  int stops = 0;
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    const Surface& s = surfaces[i];
    const bool last = i + 1 == surfaces.size();
    if (!std::isfinite(s.curvature_per_mm)) reject_surface(i, "curvature_per_mm", s.curvature_per_mm, "must be finite (use 0 for a plane)");
    if (!(last && image_at_paraxial_focus)) {
      if (!std::isfinite(s.thickness_mm)) reject_surface(i, "thickness_mm", s.thickness_mm, "must be finite");
    }
    if (s.semi_diameter_mm) {
      if (!std::isfinite(*s.semi_diameter_mm) || *s.semi_diameter_mm <= 0.0) {
        reject_surface(i, "semi_diameter_mm", *s.semi_diameter_mm, "must be finite and > 0");
      }
      // A sphere cannot be wider than its radius: z(r) is undefined for r > |R|.
      const double widest = s.max_semi_diameter_mm();
      if (*s.semi_diameter_mm > widest * (1.0 + 1e-12)) {
        reject_surface(i, "semi_diameter_mm", *s.semi_diameter_mm,
                       "larger than the surface allows (" + format_number(widest) + " mm for this radius and conic)");
      }
    }
    if (s.aperture) {
      const SurfaceAperture& a = *s.aperture;
      const bool circle = a.shape == SurfaceAperture::Shape::Circular;
      if (!std::isfinite(a.half_x_mm) || !(a.half_x_mm > 0.0)) {
        reject_surface(i, circle ? "aperture.radius_mm" : "aperture.half_x_mm", a.half_x_mm, "must be finite and > 0");
      }
      if (!circle && (!std::isfinite(a.half_y_mm) || !(a.half_y_mm > 0.0))) {
        reject_surface(i, "aperture.half_y_mm", a.half_y_mm, "must be finite and > 0");
      }
      if (!std::isfinite(a.min_radius_mm) || a.min_radius_mm < 0.0 || (a.min_radius_mm > 0.0 && (!circle || a.obscuration))) {
        reject_surface(i, "aperture.min_radius_mm", a.min_radius_mm, "must be >= 0, and only on a circular aperture that is not an obscuration");
      }
      if (circle && a.min_radius_mm >= a.half_x_mm) {
        reject_surface(i, "aperture.min_radius_mm", a.min_radius_mm, "must be smaller than the radius " + format_number(a.half_x_mm) + " mm");
      }
      if (!std::isfinite(a.decenter_x_mm)) reject_surface(i, "aperture.decenter_x_mm", a.decenter_x_mm, "must be finite");
      if (!std::isfinite(a.decenter_y_mm)) reject_surface(i, "aperture.decenter_y_mm", a.decenter_y_mm, "must be finite");
    }
    if (!std::isfinite(s.conic)) reject_surface(i, "conic", s.conic, "must be finite");
    for (std::size_t j = 0; j < s.even_asphere.size(); ++j) {
      if (!std::isfinite(s.even_asphere[j])) reject_surface(i, "even_asphere.a" + std::to_string(2 * (j + 1)), s.even_asphere[j], "must be finite");
    }
    if (s.material.kind == MaterialSpec::Kind::Model) {
      if (!std::isfinite(s.material.nd) || s.material.nd < 1.0 || s.material.nd > 5.0) {
        reject_surface(i, "material.nd", s.material.nd, "must lie in [1, 5]");
      }
      if (s.material.vd && (!std::isfinite(*s.material.vd) || *s.material.vd <= 0.0)) {
        reject_surface(i, "material.vd", *s.material.vd, "must be finite and > 0");
      }
    }
    if (s.is_stop) ++stops;
    if (!std::isfinite(s.curvature_x_per_mm)) reject_surface(i, "curvature_x_per_mm", s.curvature_x_per_mm, "must be finite (0: flat in x)");
    if (!std::isfinite(s.conic_x)) reject_surface(i, "conic_x", s.conic_x, "must be finite");
    if (s.kind == SurfaceKind::Biconic && s.has_asphere()) {
      throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": a biconic surface takes no even-asphere terms (use a toroidal "
                              "surface for a polynomial y profile)");
    }
    if (s.kind != SurfaceKind::Toroidal && s.kind != SurfaceKind::Biconic && (s.curvature_x_per_mm != 0.0 || s.conic_x != 0.0)) {
      throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": curvature_x_per_mm and conic_x belong to toroidal and biconic "
                              "surfaces, not to a " + std::string(lensmith::to_string(s.kind)) + " surface");
    }
    if (s.kind == SurfaceKind::Toroidal && s.conic_x != 0.0) {
      throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": a toroidal surface has no x conic (its x section is the circle "
                              "of its radius of rotation); use a biconic surface");
    }
    if (s.is_coordinate_break()) {
      const CoordinateBreak& b = s.coordinate_break;
      const std::string at = "coordinate_break.";
      for (const auto& [key, value] : {std::pair{"decenter_x_mm", b.decenter_x_mm}, std::pair{"decenter_y_mm", b.decenter_y_mm},
                                       std::pair{"tilt_x_deg", b.tilt_x_deg}, std::pair{"tilt_y_deg", b.tilt_y_deg},
                                       std::pair{"tilt_z_deg", b.tilt_z_deg}}) {
        if (!std::isfinite(value)) reject_surface(i, at + key, value, "must be finite");
      }
      if (s.mirror) throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": a coordinate break cannot be a mirror (it has no shape)");
      if (s.is_stop) throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": a coordinate break cannot be the stop (it has no aperture)");
      if (s.curvature_per_mm != 0.0 || s.conic != 0.0 || s.has_asphere()) {
        throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": a coordinate break has no shape (curvature, conic and "
                                "asphere terms must be 0)");
      }
      if (s.material.kind != MaterialSpec::Kind::Air) {
        throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": a coordinate break has no material of its own (the medium "
                                "before it continues); give it none");
      }
    } else if (!s.coordinate_break.is_identity()) {
      throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": decentres and tilts belong to a coordinate break surface");
    }
    if (s.mirror && s.material.kind != MaterialSpec::Kind::Air) {
      throw PrescriptionError(surface_subject(i), "surface " + std::to_string(i + 1) + ": a mirror has no material of its own (the medium before it "
                              "continues after the reflection); give it none");
    }
  }
  if (stops > 1) throw PrescriptionError(ErrorSubject{0, "surfaces", -1}, "surfaces: " + std::to_string(stops) + " surfaces are flagged as the stop; at most one may be");

  if (!(object_distance_mm > 0.0)) reject_system("object_distance_mm", object_distance_mm, "must be > 0 (or infinity)");

  if (wavelengths_nm.empty()) throw PrescriptionError(ErrorSubject{0, "wavelengths_nm", -1}, "wavelengths_nm: at least one wavelength is needed");
  for (std::size_t i = 0; i < wavelengths_nm.size(); ++i) {
    const double w = wavelengths_nm[i];
    if (!(w > kMinWavelength_nm && w < kMaxWavelength_nm)) {
      reject_system("wavelengths_nm[" + std::to_string(i) + "]", w, "must lie in (100, 20000) nm", {0, "wavelengths_nm", static_cast<int>(i)});
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (wavelengths_nm[j] == w) reject_system("wavelengths_nm[" + std::to_string(i) + "]", w, "appears twice", {0, "wavelengths_nm", static_cast<int>(i)});
    }
  }
  if (primary_wavelength_index >= wavelengths_nm.size()) {
    throw PrescriptionError(ErrorSubject{0, "primary", -1}, "primary wavelength index " + std::to_string(primary_wavelength_index + 1) + " is beyond the " +
                            std::to_string(wavelengths_nm.size()) + " wavelengths given");
  }

  switch (aperture.kind) {
    case ApertureSpec::Kind::EntrancePupilDiameter:
      if (!std::isfinite(aperture.value) || aperture.value <= 0.0) reject_system("aperture.entrance_pupil_diameter_mm", aperture.value, "must be finite and > 0");
      break;
    case ApertureSpec::Kind::ImageSpaceFNumber:
      if (!std::isfinite(aperture.value) || aperture.value <= 0.0) reject_system("aperture.f_number", aperture.value, "must be finite and > 0");
      break;
    case ApertureSpec::Kind::ParaxialWorkingFNumber:
      if (!std::isfinite(aperture.value) || aperture.value <= 0.0) {
        reject_system("aperture.paraxial_working_f_number", aperture.value, "must be finite and > 0");
      }
      break;
    case ApertureSpec::Kind::ObjectSpaceNA:
    case ApertureSpec::Kind::ObjectConeAngleDeg: {
      const bool na = aperture.kind == ApertureSpec::Kind::ObjectSpaceNA;
      const std::string key = na ? "aperture.object_space_na" : "aperture.object_cone_angle_deg";
      if (std::isinf(object_distance_mm)) {
        reject_system(key, aperture.value, "needs a finite object distance (the object is at infinity: give an entrance-pupil diameter or f-number)");
      }
      if (!std::isfinite(aperture.value) || aperture.value <= 0.0) reject_system(key, aperture.value, "must be finite and > 0");
      if (!na && aperture.value >= 90.0) reject_system(key, aperture.value, "must be below 90 degrees");
      if (na && aperture.value >= object_medium.index(primary_wavelength_nm())) {
        reject_system(key, aperture.value, "must be below the object-space index " + format_number(object_medium.index(primary_wavelength_nm())));
      }
      break;
    }
    case ApertureSpec::Kind::FloatByStop: {
      auto stop = flagged_stop_index();
      if (stop && !surfaces[*stop].semi_diameter_mm) {
        throw PrescriptionError(ErrorSubject{0, "aperture", -1}, "aperture: floats by stop size, but the stop (surface " + std::to_string(*stop + 1) +
                                ") has no semi_diameter_mm");
      }
      if (!stop) {
        bool any = false;
        for (const auto& s : surfaces) any = any || s.semi_diameter_mm.has_value();
        if (!any) throw PrescriptionError(ErrorSubject{0, "aperture", -1}, "aperture: floats by stop size, but no surface is flagged as stop and none has a semi_diameter_mm");
      }
      break;
    }
  }

  if (object_space_telecentric) {
    if (std::isinf(object_distance_mm)) {
      throw PrescriptionError(ErrorSubject{0, "object_space_telecentric", -1}, "object_space_telecentric: needs a finite object distance (the object is at infinity)");
    }
    if (aperture.kind != ApertureSpec::Kind::ObjectSpaceNA && aperture.kind != ApertureSpec::Kind::ObjectConeAngleDeg) {
      throw PrescriptionError(ErrorSubject{0, "aperture", -1}, "aperture: an object-space telecentric lens has its entrance pupil at infinity; give its "
                              "aperture as an object-space NA or cone angle, not " + aperture.to_string());
    }
    if (field && field->kind == FieldSpec::Kind::AngleDeg) {
      throw PrescriptionError(ErrorSubject{0, "field", -1}, "field: an object-space telecentric lens has every chief ray parallel to the axis; give "
                              "its field as object or image heights, not angles");
    }
  }
  if (field) {
    if (field->values.empty()) throw PrescriptionError(ErrorSubject{0, "field", -1}, "field: at least one field point is needed");
    for (std::size_t i = 0; i < field->values.size(); ++i) {
      const double v = field->values[i];
      if (!std::isfinite(v)) reject_system("field.values[" + std::to_string(i) + "]", v, "must be finite", {0, "field.values", static_cast<int>(i)});
      if (field->kind == FieldSpec::Kind::AngleDeg && std::abs(v) >= 90.0) {
        reject_system("field.max_angle_deg", v, "must lie in (-90, 90) degrees");
      }
    }
    if (!field->vignetting.empty() && field->vignetting.size() != field->values.size()) {
      throw PrescriptionError(ErrorSubject{0, "field.vignetting", -1}, "field.vignetting: " + std::to_string(field->vignetting.size()) + " sets of vignetting factors for " +
                              std::to_string(field->values.size()) + " field points; give one per point");
    }
    for (std::size_t i = 0; i < field->vignetting.size(); ++i) {
      const VignettingFactors& v = field->vignetting[i];
      const std::string at = "field.vignetting[" + std::to_string(i) + "].";
      for (const auto& [key, value] : {std::pair{"vdx", v.vdx}, std::pair{"vdy", v.vdy}, std::pair{"van_deg", v.van_deg}}) {
        if (!std::isfinite(value)) reject_system(at + key, value, "must be finite", {0, "field.vignetting", static_cast<int>(i)});
      }
      for (const auto& [key, value] : {std::pair{"vcx", v.vcx}, std::pair{"vcy", v.vcy}}) {
        if (!(value < 1.0) || !std::isfinite(value)) {
          reject_system(at + key, value, "must be finite and below 1 (1 closes the pupil)", {0, "field.vignetting", static_cast<int>(i)});
        }
      }
    }
    if (field->kind == FieldSpec::Kind::ObjectHeightMm && std::isinf(object_distance_mm)) {
      throw PrescriptionError(ErrorSubject{0, "field", -1}, "field: an object-height field needs a finite object distance (the object is at infinity)");
    }
  }
}

void Prescription::resolve_materials(const GlassCatalog& catalogue) {
  try {
    object_medium = object_material.resolve(catalogue);
  } catch (const GlassError& e) {
    throw GlassError(ErrorSubject{0, "object", -1}, std::string("object space: ") + e.what());
  }
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    if (surfaces[i].mirror || surfaces[i].is_coordinate_break()) {
      // The medium before it continues: after a mirror the light goes back into it.
      surfaces[i].medium = i == 0 ? object_medium : surfaces[i - 1].medium;
      continue;
    }
    try {
      surfaces[i].medium = surfaces[i].material.resolve(catalogue);
    } catch (const GlassError& e) {
      throw GlassError(surface_subject(i, "material"), "surface " + std::to_string(i + 1) + ": " + e.what());
    }
  }
}

Prescription Prescription::scaled(double factor) const {
  if (!std::isfinite(factor) || factor <= 0.0) reject_system("scale factor", factor, "must be finite and > 0");
  Prescription p = *this;
  for (Surface& s : p.surfaces) {
    s.curvature_per_mm /= factor;
    s.curvature_x_per_mm /= factor;
    s.coordinate_break.decenter_x_mm *= factor;
    s.coordinate_break.decenter_y_mm *= factor;
    s.thickness_mm *= factor;
    if (s.semi_diameter_mm) *s.semi_diameter_mm *= factor;
    if (s.aperture) {
      s.aperture->min_radius_mm *= factor;
      s.aperture->half_x_mm *= factor;
      s.aperture->half_y_mm *= factor;
      s.aperture->decenter_x_mm *= factor;
      s.aperture->decenter_y_mm *= factor;
    }
    // z = a_{2k} r^{2k} scales as length: a_{2k} -> a_{2k} * factor^(1 - 2k).
    for (std::size_t j = 0; j < s.even_asphere.size(); ++j) {
      s.even_asphere[j] *= std::pow(factor, 1.0 - 2.0 * static_cast<double>(j + 1));
    }
  }
  p.object_distance_mm *= factor;
  if (p.aperture.kind == ApertureSpec::Kind::EntrancePupilDiameter) p.aperture.value *= factor;
  if (p.field && p.field->kind != FieldSpec::Kind::AngleDeg) {
    for (double& v : p.field->values) v *= factor;
  }
  return p;
}

std::string Prescription::to_string() const {
  std::ostringstream os;
  os << (name.empty() ? std::string("(unnamed lens)") : name) << "\n";
  os << "  object distance: " << (std::isinf(object_distance_mm) ? std::string("infinity") : format_number(object_distance_mm) + " mm")
     << ", aperture: " << aperture.to_string() << ", field: " << (field ? field->to_string() : std::string("none")) << "\n";
  os << "  wavelengths (nm):";
  for (std::size_t i = 0; i < wavelengths_nm.size(); ++i) {
    os << ' ' << format_number(wavelengths_nm[i]) << (i == primary_wavelength_index ? "*" : "");
  }
  os << "\n";
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    os << "  " << (i + 1) << ": " << surfaces[i].to_string();
    if (i + 1 == surfaces.size() && image_at_paraxial_focus) os << " (image at paraxial focus)";
    os << "\n";
  }
  return os.str();
}

}  // namespace lensmith

// Published designs built from their printed tables; see reference_lenses.h.
#include "reference_lenses.h"

#include <cmath>

#include "lensmith/core/units.h"
#include "lensmith/glass/glass_catalog.h"

namespace lensmith::testing {

Surface make_surface(double radius_mm, double thickness_mm, const MaterialSpec& material,
                     std::optional<double> semi_diameter_mm) {
  Surface s;
  s.curvature_per_mm = std::isinf(radius_mm) ? 0.0 : 1.0 / radius_mm;
  s.thickness_mm = thickness_mm;
  s.material = material;
  s.medium = material.resolve(GlassCatalog::builtin());
  s.semi_diameter_mm = semi_diameter_mm;
  return s;
}

namespace {
// Model glass from Smith's n_d and delta n = n_F - n_C (Vd = (n_d - 1) / delta n).
MaterialSpec smith_glass(double nd, double delta_n) { return MaterialSpec::model(nd, (nd - 1.0) / delta_n); }
}  // namespace

// W. J. Smith, Modern Optical Engineering, 4th ed., ch. 6 (REFERENCE-VALUES.md section 1).
Prescription smith_cooke_triplet() {
  const MaterialSpec sk4 = smith_glass(1.61272, 0.010450);
  const MaterialSpec sf2 = smith_glass(1.64769, 0.019151);
  const MaterialSpec air = MaterialSpec::air();
  Prescription p;
  p.name = "Smith Cooke triplet";
  p.source = "W. J. Smith, Modern Optical Engineering, 4th ed., ch. 6";
  p.surfaces = {
      make_surface(37.40, 5.90, sk4, 14.7),     make_surface(-341.48, 12.93, air, 14.7),
      make_surface(-42.65, 2.50, sf2, 10.8),    make_surface(36.40, 2.00, air, 10.8),
      make_surface(kInfinity, 9.85, air, 10.3), make_surface(204.52, 5.90, sk4, 11.6),
      make_surface(-37.05, 77.405, air, 11.6),
  };
  p.surfaces[4].is_stop = true;
  p.image_at_paraxial_focus = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 29.2};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {deg_from_rad(std::atan(0.21))}};
  return p;
}

// Sasian triplet, ray-optics docs/source/examples/SasianTriplet (REFERENCE-VALUES.md section 2).
Prescription sasian_triplet() {
  const MaterialSpec lak9 = MaterialSpec::catalog("N-LAK9", "SCHOTT");
  const MaterialSpec sf5 = MaterialSpec::catalog("N-SF5", "SCHOTT");
  const MaterialSpec air = MaterialSpec::air();
  Prescription p;
  p.name = "Sasian triplet";
  p.source = "ray-optics documentation, SasianTriplet.rst";
  p.surfaces = {
      make_surface(23.713, 4.831, lak9, 10.009),  make_surface(7331.288, 5.86, air, 8.9482),
      make_surface(-24.456, 0.975, sf5, 4.7919),  make_surface(21.896, 4.822, air, 4.7761),
      make_surface(86.759, 3.127, lak9, 8.0217),  make_surface(-20.4942, 41.2365, air, 8.3321),
  };
  p.surfaces[2].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 12.5};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {0.0, 14.0, 20.0}};
  p.wavelengths_nm = {486.1327, 587.5618, 656.2725};
  p.primary_wavelength_index = 1;
  return p;
}

// Angenieux double Gauss, US 2,701,982 (1953), as in the lentil lens database (entry 0001),
// with the patent's glass types taken from the Schott catalogue.
Prescription angenieux_double_gauss() {
  const MaterialSpec sf5 = MaterialSpec::catalog("N-SF5", "SCHOTT");
  const MaterialSpec baf10 = MaterialSpec::catalog("N-BAF10", "SCHOTT");
  const MaterialSpec lak9 = MaterialSpec::catalog("N-LAK9", "SCHOTT");
  const MaterialSpec sf15 = MaterialSpec::catalog("SF15", "SCHOTT");
  const MaterialSpec sk16 = MaterialSpec::catalog("N-SK16", "SCHOTT");
  const MaterialSpec air = MaterialSpec::air();
  Prescription p;
  p.surfaces = {
      make_surface(164.13, 10.99, sf5, 54),        make_surface(559.2, 0.23, air, 54),
      make_surface(100.12, 11.45, baf10, 51),      make_surface(213.54, 0.23, air, 51),
      make_surface(58.04, 22.95, lak9, 41),        make_surface(2551.1, 2.58, sf5, 41),
      make_surface(32.39, 15.66, air, 27),         make_surface(kInfinity, 15.0, air, 25.5),
      make_surface(-40.42, 2.74, sf15, 25),        make_surface(192.98, 27.92, sk16, 36),
      make_surface(-55.53, 0.23, air, 36),         make_surface(192.98, 7.98, lak9, 35),
      make_surface(-225.3, 0.23, air, 35),         make_surface(175.09, 8.48, lak9, 35),
      make_surface(-203.55, 55.724, air, 35),
  };
  p.surfaces[7].is_stop = true;
  p.aperture = ApertureSpec{ApertureSpec::Kind::FloatByStop, 0.0};
  p.field = FieldSpec{FieldSpec::Kind::AngleDeg, {12.0}};
  return p;
}

Prescription cartesian_ellipsoid(double defocus_mm) {
  using C = CartesianEllipsoid;
  Prescription p;
  p.name = "Cartesian ellipsoid";
  Surface s;
  s.curvature_per_mm = 1.0 / C::kRadiusMm;
  s.conic = -1.0 / (C::kIndex * C::kIndex);
  s.thickness_mm = C::kFocusMm + defocus_mm;
  s.material = MaterialSpec::model(C::kIndex, std::nullopt);
  s.is_stop = true;
  s.semi_diameter_mm = 12.0;
  p.surfaces = {s};
  p.aperture = ApertureSpec{ApertureSpec::Kind::EntrancePupilDiameter, 20.0};
  p.wavelengths_nm = {kWavelengthD_nm};
  p.primary_wavelength_index = 0;
  p.resolve_materials(GlassCatalog::builtin());
  return p;
}

}  // namespace lensmith::testing

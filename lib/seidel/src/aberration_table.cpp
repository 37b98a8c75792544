#include "lensmith/seidel/aberration_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/core/grid_interval.h"
#include "lensmith/core/units.h"

namespace lensmith {

namespace {

AberrationCoefficients lerp(const AberrationCoefficients& a, const AberrationCoefficients& b, double t) {
  auto mix = [t](double x, double y) { return x + (y - x) * t; };
  AberrationCoefficients c;
  c.B_mm = mix(a.B_mm, b.B_mm);
  c.C_mm = mix(a.C_mm, b.C_mm);
  c.D_mm = mix(a.D_mm, b.D_mm);
  c.E_mm = mix(a.E_mm, b.E_mm);
  c.F_mm = mix(a.F_mm, b.F_mm);
  c.pupil_radius_mm = mix(a.pupil_radius_mm, b.pupil_radius_mm);
  c.max_field_tangent = mix(a.max_field_tangent, b.max_field_tangent);
  c.exit_pupil_to_image_mm = mix(a.exit_pupil_to_image_mm, b.exit_pupil_to_image_mm);
  const bool inf_a = std::isinf(a.object_to_entrance_pupil_mm);
  const bool inf_b = std::isinf(b.object_to_entrance_pupil_mm);
  c.object_to_entrance_pupil_mm = (inf_a || inf_b) ? (t < 0.5 ? a.object_to_entrance_pupil_mm : b.object_to_entrance_pupil_mm)
                                                   : mix(a.object_to_entrance_pupil_mm, b.object_to_entrance_pupil_mm);
  return c;
}

AberrationSample lerp(const AberrationSample& a, const AberrationSample& b, double t) {
  AberrationSample s;
  s.wavelength_nm = a.wavelength_nm + (b.wavelength_nm - a.wavelength_nm) * t;
  s.object_distance_mm = a.object_distance_mm;
  s.coefficients = lerp(a.coefficients, b.coefficients, t);
  s.paraxial = interpolate(a.paraxial, b.paraxial, t);
  return s;
}


}  // namespace

void AberrationTableOptions::validate() const {
  if (!(min_wavelength_nm > 100.0 && max_wavelength_nm < 20000.0 && min_wavelength_nm < max_wavelength_nm)) {
    throw OptionsError("AberrationTableOptions: wavelengths must satisfy 100 < min_wavelength_nm < max_wavelength_nm < 20000");
  }
  if (wavelength_samples < 2) throw OptionsError("AberrationTableOptions::wavelength_samples = " + std::to_string(wavelength_samples) + ": must be >= 2");
  if (object_distances_mm.empty()) throw OptionsError("AberrationTableOptions::object_distances_mm: give at least one distance");
  for (double d : object_distances_mm) {
    if (!(d > 0.0)) throw OptionsError("AberrationTableOptions::object_distances_mm: " + std::to_string(d) + " must be > 0 (or infinity)");
  }
  seidel.validate();
}

AberrationTable::AberrationTable(const Prescription& lens, const AberrationTableOptions& options) {
  options.validate();
  const int n = options.wavelength_samples;
  for (int i = 0; i < n; ++i) {
    wavelengths_nm_.push_back(options.min_wavelength_nm + (options.max_wavelength_nm - options.min_wavelength_nm) * i / (n - 1));
  }
  distances_mm_ = options.object_distances_mm;
  // Sorted by inverse distance (infinity first): the interpolation variable.
  std::sort(distances_mm_.begin(), distances_mm_.end(), [](double a, double b) { return inverse_per_mm(a) < inverse_per_mm(b); });
  for (double d : distances_mm_) inverse_distances_per_mm_.push_back(inverse_per_mm(d));
  samples_.reserve(wavelengths_nm_.size() * distances_mm_.size());
  for (double d : distances_mm_) {
    SpectralTableOptions spectral;
    spectral.min_wavelength_nm = options.min_wavelength_nm;
    spectral.max_wavelength_nm = options.max_wavelength_nm;
    spectral.samples = n;
    spectral.object_distance_mm = d;
    const ParaxialSpectralTable first_order(lens, spectral);
    for (int i = 0; i < n; ++i) {
      SeidelOptions so = options.seidel;
      so.wavelength_nm = wavelengths_nm_[static_cast<std::size_t>(i)];
      so.object_distance_mm = d;
      const SeidelAnalysis seidel(lens, so);
      AberrationSample s;
      s.wavelength_nm = so.wavelength_nm;
      s.object_distance_mm = d;
      s.coefficients = AberrationCoefficients::from(seidel);
      s.paraxial = first_order.samples()[static_cast<std::size_t>(i)];
      samples_.push_back(s);
    }
  }
}

AberrationTable::Cell AberrationTable::cell(double wavelength_nm, double object_distance_mm) const {
  const auto [i, ti] = grid_interval(wavelengths_nm_, wavelength_nm);
  const auto [j, tj] = grid_interval(inverse_distances_per_mm_, inverse_per_mm(object_distance_mm));
  return {i, std::min(i + 1, wavelengths_nm_.size() - 1), ti, j, std::min(j + 1, distances_mm_.size() - 1), tj};
}

AberrationCoefficients AberrationTable::coefficients_at(double wavelength_nm, double object_distance_mm) const {
  const Cell c = cell(wavelength_nm, object_distance_mm);
  const AberrationCoefficients near_lambda = lerp(sample(c.i, c.j).coefficients, sample(c.i1, c.j).coefficients, c.ti);
  const AberrationCoefficients far_lambda = lerp(sample(c.i, c.j1).coefficients, sample(c.i1, c.j1).coefficients, c.ti);
  return lerp(near_lambda, far_lambda, c.tj);
}

AberrationSample AberrationTable::at(double wavelength_nm, double object_distance_mm) const {
  const Cell c = cell(wavelength_nm, object_distance_mm);
  const AberrationSample near_lambda = lerp(sample(c.i, c.j), sample(c.i1, c.j), c.ti);
  const AberrationSample far_lambda = lerp(sample(c.i, c.j1), sample(c.i1, c.j1), c.ti);
  AberrationSample s = lerp(near_lambda, far_lambda, c.tj);
  s.object_distance_mm = object_distance_mm;
  return s;
}

std::string AberrationTable::to_string() const {
  std::ostringstream os;
  char line[200];
  os << "Born & Wolf coefficients (mm) over wavelength and object distance\n";
  std::snprintf(line, sizeof line, "%12s %10s %12s %12s %12s %12s %12s\n", "distance mm", "lambda nm", "B", "C", "D", "E", "F");
  os << line;
  for (std::size_t j = 0; j < distances_mm_.size(); ++j) {
    for (std::size_t i = 0; i < wavelengths_nm_.size(); ++i) {
      const AberrationCoefficients& c = sample(i, j).coefficients;
      std::snprintf(line, sizeof line, "%12.6g %10.3f %12.6g %12.6g %12.6g %12.6g %12.6g\n", distances_mm_[j], wavelengths_nm_[i], c.B_mm, c.C_mm,
                    c.D_mm, c.E_mm, c.F_mm);
      os << line;
    }
  }
  return os.str();
}

}  // namespace lensmith

// First-order parameters sampled over wavelength. The stop, the EPD of an EPD or F/# aperture and
// the object distance are fixed by one ParaxialSystem at the primary wavelength; each sample then
// runs only the allocation-free kernel (paraxial_kernel.h) on precomputed curvatures and thicknesses.
#include "lensmith/paraxial/paraxial_spectral_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "lensmith/core/errors.h"
#include "lensmith/paraxial/paraxial_system.h"
#include "paraxial_kernel.h"

namespace lensmith {

namespace {

std::string number(double value, int decimals) { return paraxial_detail::format_fixed(value, decimals); }
std::string padded(const std::string& text, std::size_t width) { return paraxial_detail::right_aligned(text, width); }

}  // namespace

void SpectralTableOptions::validate() const {
  if (!(min_wavelength_nm > 100.0 && min_wavelength_nm < 20000.0)) {
    throw OptionsError("SpectralTableOptions::min_wavelength_nm = " + number(min_wavelength_nm, 4) +
                       ": must be in (100, 20000) nm");
  }
  if (!(max_wavelength_nm > min_wavelength_nm && max_wavelength_nm < 20000.0)) {
    throw OptionsError("SpectralTableOptions::max_wavelength_nm = " + number(max_wavelength_nm, 4) +
                       ": must be > min_wavelength_nm (" + number(min_wavelength_nm, 4) + ") and < 20000 nm");
  }
  if (samples < 2) {
    throw OptionsError("SpectralTableOptions::samples = " + std::to_string(samples) + ": must be >= 2");
  }
  if (object_distance_mm && !(*object_distance_mm > 0.0)) {
    throw OptionsError("SpectralTableOptions::object_distance_mm = " + number(*object_distance_mm, 6) +
                       ": must be > 0 (+infinity for an object at infinity)");
  }
}

ParaxialSpectralTable::ParaxialSpectralTable(const Prescription& lens, const SpectralTableOptions& options) {
  options.validate();
  ParaxialOptions primary_options;
  primary_options.object_distance_mm = options.object_distance_mm;
  // Validates the lens and fixes what does not change with wavelength: stop, EPD spec, object.
  const ParaxialSystem primary(lens, primary_options);
  const double object_distance_mm = primary.object_distance_mm();
  const std::size_t stop_index = static_cast<std::size_t>(primary.stop_surface() - 1);
  const bool epd_floats = lens.aperture.kind == ApertureSpec::Kind::FloatByStop;
  const double stop_semi_diameter_mm = lens.surfaces[stop_index].semi_diameter_mm.value_or(0.0);
  const double fixed_epd_mm = primary.entrance_pupil().diameter_mm;
  const double z_last_mm = primary.z_last_surface_mm();

  const std::size_t count = lens.surfaces.size();
  std::vector<double> curvatures(count), thicknesses(count), indices(count);
  std::vector<const Glass*> media(count);
  const std::vector<double> signs = paraxial_detail::reflection_signs(lens);
  for (std::size_t k = 0; k < count; ++k) {
    curvatures[k] = lens.surfaces[k].paraxial_curvature_per_mm();
    thicknesses[k] = lens.surfaces[k].thickness_mm;
    media[k] = &lens.surfaces[k].medium;
  }

  samples_.resize(static_cast<std::size_t>(options.samples));
  const double step_nm = (options.max_wavelength_nm - options.min_wavelength_nm) / (options.samples - 1);
  for (std::size_t s = 0; s < samples_.size(); ++s) {
    // The last sample is set to the maximum exactly, free of the rounding in min + step * s.
    const double wavelength_nm = s + 1 == samples_.size()
                                     ? options.max_wavelength_nm
                                     : options.min_wavelength_nm + step_nm * static_cast<double>(s);
    bool extrapolated = !lens.object_medium.covers(wavelength_nm);
    for (std::size_t k = 0; k < count; ++k) {
      indices[k] = signs[k] * media[k]->index(wavelength_nm);
      extrapolated = extrapolated || !media[k]->covers(wavelength_nm);
    }
    const double n_object = lens.object_medium.index(wavelength_nm);
    const double n_image = indices[count - 1];

    const paraxial_detail::KernelMatrices m =
        paraxial_detail::compose_matrices(curvatures, thicknesses, indices, n_object, stop_index);
    const paraxial_detail::CardinalPoints c = paraxial_detail::cardinal_points(m, n_object, n_image, z_last_mm);
    const paraxial_detail::PupilImages p = paraxial_detail::pupil_images(m, n_object, n_image, z_last_mm);
    const paraxial_detail::ImageConjugate image =
        paraxial_detail::image_conjugate(m.system, n_object, n_image, object_distance_mm);

    ParaxialSample& out = samples_[s];
    out.wavelength_nm = wavelength_nm;
    out.efl_mm = 1.0 / c.power_per_mm;
    out.bfl_mm = c.z_rear_focal_mm - z_last_mm;
    out.ffl_mm = c.z_front_focal_mm;
    out.z_front_principal_mm = c.z_front_principal_mm;
    out.z_rear_principal_mm = c.z_rear_principal_mm;
    out.z_entrance_pupil_mm = p.z_entrance_mm;
    out.entrance_pupil_diameter_mm =
        epd_floats ? 2.0 * stop_semi_diameter_mm * std::abs(p.entrance_magnification) : fixed_epd_mm;
    out.z_exit_pupil_mm = p.z_exit_mm;
    out.exit_pupil_diameter_mm =
        out.entrance_pupil_diameter_mm * std::abs(p.exit_magnification / p.entrance_magnification);
    out.image_distance_mm = image.image_distance_mm;
    out.magnification = image.magnification;
    out.extrapolated = extrapolated;
  }
}

ParaxialSample ParaxialSpectralTable::at(double wavelength_nm) const {
  const ParaxialSample& first = samples_.front();
  const ParaxialSample& last = samples_.back();
  if (!(wavelength_nm > first.wavelength_nm)) return first;  // NaN clamps to the first sample too
  if (wavelength_nm >= last.wavelength_nm) return last;
  // Samples are evenly spaced: find the interval directly.
  const double step_nm = (last.wavelength_nm - first.wavelength_nm) / static_cast<double>(samples_.size() - 1);
  const std::size_t lo = std::min(static_cast<std::size_t>((wavelength_nm - first.wavelength_nm) / step_nm),
                                  samples_.size() - 2);
  const ParaxialSample& a = samples_[lo];
  const ParaxialSample& b = samples_[lo + 1];
  ParaxialSample out = interpolate(a, b, (wavelength_nm - a.wavelength_nm) / (b.wavelength_nm - a.wavelength_nm));
  out.wavelength_nm = wavelength_nm;  // exact, not re-derived from the interpolation
  return out;
}

ParaxialSample interpolate(const ParaxialSample& a, const ParaxialSample& b, double t) {
  auto lerp = [t](double x, double y) { return x + t * (y - x); };
  ParaxialSample out;
  out.wavelength_nm = lerp(a.wavelength_nm, b.wavelength_nm);
  out.efl_mm = lerp(a.efl_mm, b.efl_mm);
  out.bfl_mm = lerp(a.bfl_mm, b.bfl_mm);
  out.ffl_mm = lerp(a.ffl_mm, b.ffl_mm);
  out.z_front_principal_mm = lerp(a.z_front_principal_mm, b.z_front_principal_mm);
  out.z_rear_principal_mm = lerp(a.z_rear_principal_mm, b.z_rear_principal_mm);
  out.z_entrance_pupil_mm = lerp(a.z_entrance_pupil_mm, b.z_entrance_pupil_mm);
  out.entrance_pupil_diameter_mm = lerp(a.entrance_pupil_diameter_mm, b.entrance_pupil_diameter_mm);
  out.z_exit_pupil_mm = lerp(a.z_exit_pupil_mm, b.z_exit_pupil_mm);
  out.exit_pupil_diameter_mm = lerp(a.exit_pupil_diameter_mm, b.exit_pupil_diameter_mm);
  out.image_distance_mm = lerp(a.image_distance_mm, b.image_distance_mm);
  out.magnification = lerp(a.magnification, b.magnification);
  out.extrapolated = (t > 0.0 && b.extrapolated) || (t < 1.0 && a.extrapolated);
  return out;
}

std::string ParaxialSpectralTable::to_string() const {
  std::ostringstream os;
  os << "Paraxial data by wavelength (z in mm from the vertex of surface 1; * = glass extrapolated)\n";
  os << padded("lambda (nm)", 12) << padded("EFL (mm)", 12) << padded("BFL (mm)", 12) << padded("FFL (mm)", 12)
     << padded("z P", 11) << padded("z P'", 11) << padded("z EP", 11) << padded("EPD", 10) << padded("z XP", 11)
     << padded("XPD", 10) << padded("img dist", 12) << padded("magn.", 11) << '\n';
  for (const ParaxialSample& s : samples_) {
    os << padded(number(s.wavelength_nm, 2) + (s.extrapolated ? "*" : " "), 12) << padded(number(s.efl_mm, 4), 12)
       << padded(number(s.bfl_mm, 4), 12) << padded(number(s.ffl_mm, 4), 12)
       << padded(number(s.z_front_principal_mm, 3), 11) << padded(number(s.z_rear_principal_mm, 3), 11)
       << padded(number(s.z_entrance_pupil_mm, 3), 11) << padded(number(s.entrance_pupil_diameter_mm, 3), 10)
       << padded(number(s.z_exit_pupil_mm, 3), 11) << padded(number(s.exit_pupil_diameter_mm, 3), 10)
       << padded(number(s.image_distance_mm, 4), 12) << padded(number(s.magnification, 5), 11) << '\n';
  }
  return os.str();
}

}  // namespace lensmith

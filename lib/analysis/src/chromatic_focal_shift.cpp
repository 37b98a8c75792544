// Paraxial longitudinal chromatic focal shift (OpticStudio "Chromatic Focal Shift"; Welford sec. 8.2).
#include "lensmith/analysis/chromatic_focal_shift.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "analysis_detail.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/units.h"
#include "lensmith/paraxial/paraxial_system.h"

namespace lensmith {

using analysis_detail::fixed;

namespace {

bool valid_wavelength(double w) { return w > 100.0 && w < 20000.0; }

}  // namespace

void FocalShiftOptions::validate() const {
  analysis_detail::check_count("FocalShiftOptions::samples", samples, 2, 10001);
  if (min_nm && !valid_wavelength(*min_nm)) throw OptionsError("FocalShiftOptions::min_nm = " + fixed(*min_nm, 4) + ": must lie in (100, 20000) nm");
  if (max_nm && !valid_wavelength(*max_nm)) throw OptionsError("FocalShiftOptions::max_nm = " + fixed(*max_nm, 4) + ": must lie in (100, 20000) nm");
  if (min_nm && max_nm && !(*min_nm < *max_nm)) {
    throw OptionsError("FocalShiftOptions: min_nm = " + fixed(*min_nm, 4) + " must be below max_nm = " + fixed(*max_nm, 4));
  }
  for (std::size_t i = 0; i < wavelengths_nm.size(); ++i) {
    if (!valid_wavelength(wavelengths_nm[i])) {
      throw OptionsError("FocalShiftOptions::wavelengths_nm[" + std::to_string(i) + "] = " + fixed(wavelengths_nm[i], 4) +
                         ": must lie in (100, 20000) nm");
    }
  }
}

ChromaticFocalShift compute_chromatic_focal_shift(const Prescription& lens, const FocalShiftOptions& options) {
  options.validate();
  lens.validate();
  const std::vector<double> analysed = options.wavelengths_nm.empty() ? lens.wavelengths_nm : options.wavelengths_nm;
  ChromaticFocalShift out;
  out.lens_name = lens.name;
  out.reference_wavelength_nm = analysed.front();
  for (double w : analysed) {
    if (w == lens.primary_wavelength_nm()) out.reference_wavelength_nm = w;
  }
  double lo = options.min_nm.value_or(*std::min_element(analysed.begin(), analysed.end()));
  double hi = options.max_nm.value_or(*std::max_element(analysed.begin(), analysed.end()));
  if (!(lo < hi)) {
    throw OptionsError("chromatic focal shift: the wavelength range " + fixed(lo, 2) + " to " + fixed(hi, 2) +
                       " nm is empty: analyse more than one wavelength or give the range");
  }

  std::vector<double> wavelengths;
  for (int i = 0; i < options.samples; ++i) wavelengths.push_back(lo + (hi - lo) * i / (options.samples - 1));
  for (double w : analysed) {
    if (w >= lo && w <= hi) wavelengths.push_back(w);
  }
  wavelengths.push_back(out.reference_wavelength_nm);
  std::sort(wavelengths.begin(), wavelengths.end());
  wavelengths.erase(std::unique(wavelengths.begin(), wavelengths.end()), wavelengths.end());

  auto image_distance = [&](double wavelength) {
    ParaxialOptions p;
    p.wavelength_nm = wavelength;
    return ParaxialSystem(lens, p).image_distance_mm();
  };
  out.reference_image_distance_mm = image_distance(out.reference_wavelength_nm);
  for (double w : wavelengths) {
    FocalShiftPoint p;
    p.wavelength_nm = w;
    p.image_distance_mm = image_distance(w);
    if (!std::isfinite(p.image_distance_mm)) {
      throw ComputationError("chromatic focal shift: the paraxial image is at infinity at " + fixed(w, 2) + " nm");
    }
    p.shift_mm = p.image_distance_mm - out.reference_image_distance_mm;
    p.extrapolated = !lens.object_medium.covers(w);
    for (const Surface& s : lens.surfaces) p.extrapolated = p.extrapolated || !s.medium.covers(w);
    out.points.push_back(p);
  }
  return out;
}

double ChromaticFocalShift::range_mm() const {
  if (points.empty()) return 0.0;
  auto [lo, hi] = std::minmax_element(points.begin(), points.end(),
                                      [](const FocalShiftPoint& a, const FocalShiftPoint& b) { return a.shift_mm < b.shift_mm; });
  return hi->shift_mm - lo->shift_mm;
}

std::string ChromaticFocalShift::to_string() const {
  std::ostringstream os;
  os << "Chromatic focal shift (paraxial): " << lens_name << "\n";
  os << "Reference " << fixed(reference_wavelength_nm, 4) << " nm: paraxial image " << fixed(reference_image_distance_mm, 6)
     << " mm behind the last vertex; range of the shift " << fixed(um_from_mm(range_mm()), 3) << " um\n\n";
  char line[128];
  std::snprintf(line, sizeof line, "%14s %22s %16s\n", "lambda nm", "image distance mm", "shift um");
  os << line;
  for (const auto& p : points) {
    std::snprintf(line, sizeof line, "%14.4f %22.6f %16.3f%s\n", p.wavelength_nm, p.image_distance_mm, um_from_mm(p.shift_mm),
                  p.extrapolated ? "  (glass extrapolated)" : "");
    os << line;
  }
  return os.str();
}

}  // namespace lensmith

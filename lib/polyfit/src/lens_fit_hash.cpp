// Which prescription a fit belongs to (lens_fit.h): a hash of what the rays see, so that a fit file
// is never used with another lens.
#include <cstdio>
#include <cstring>

#include "lens_fit_stages.h"
#include "lensmith/core/units.h"

namespace lensmith {

std::string LensFit::prescription_hash(const Prescription& given) {
  // The coaxial core's (a tilt-shift lens's breaks are applied where the fit is used, not fitted: one fit
  // serves every tilt and shift of the same elements).
  const std::optional<CoaxialCore> core = coaxial_core(given);
  const Prescription& lens = core ? core->lens : given;
  // FNV-1a, 64 bit (Fowler, Noll & Vo), over the numbers the rays see.
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&](double v) {
    if (v == 0.0) v = 0.0;  // -0 and +0 hash alike
    unsigned char bytes[sizeof v];
    std::memcpy(bytes, &v, sizeof v);
    for (const unsigned char b : bytes) h = (h ^ b) * 0x100000001b3ull;
  };
  const ParaxialSystem paraxial(lens);
  const int stop = paraxial.stop_surface();
  for (const double nm : {380.0, kWavelengthD_nm, 780.0}) mix(lens.object_medium.index(nm));
  for (std::size_t k = 0; k < lens.surfaces.size(); ++k) {
    const Surface& s = lens.surfaces[k];
    mix(s.curvature_per_mm);
    mix(k + 1 < lens.surfaces.size() ? s.thickness_mm : 0.0);  // the last thickness only places the image
    mix(s.conic);
    for (const double a : s.even_asphere) mix(a);
    mix(static_cast<int>(k + 1) == stop ? -1.0 : s.semi_diameter_mm.value_or(kInfinity));
    // The other shapes' x section (not mixed for a standard surface: the hashes of fits made before
    // toroids could be fitted stay valid).
    if (s.kind != SurfaceKind::Standard) {
      mix(static_cast<double>(static_cast<int>(s.kind)));
      mix(s.curvature_x_per_mm);
      mix(s.conic_x);
    }
    for (const double nm : {380.0, kWavelengthD_nm, 780.0}) mix(s.medium.index(nm));
    // A mirror, and an explicit aperture other than the stop's (they clip instead of the semi-diameter):
    // mixed only where present, for the same reason.
    if (s.mirror) mix(-2.0);
    if (s.aperture && static_cast<int>(k + 1) != stop) {
      const SurfaceAperture& a = *s.aperture;
      mix(static_cast<double>(static_cast<int>(a.shape)));
      for (const double v : {a.obscuration ? 1.0 : 0.0, a.min_radius_mm, a.half_x_mm, a.half_y_mm, a.decenter_x_mm, a.decenter_y_mm}) mix(v);
    }
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

void LensFit::check_matches(const Prescription& lens) const {
  const std::string h = prescription_hash(lens);
  if (h != lens_hash_) {
    throw OptionsError("the fit was made for '" + lens_name_ + "' (prescription hash " + lens_hash_ +
                       "), not for '" + lens.name + "' (hash " + h + "): fit this lens with lensmith fit");
  }
}

}  // namespace lensmith
